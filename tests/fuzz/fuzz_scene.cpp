// Scene files (config/scenes/*.toml) as `covtrack regions` and `view` read them: parsed,
// their transforms put into a transform graph with every tracked edge reporting, and
// each object's 3-D hull built. Files a scene names (calibration, transform tables) are
// looked for beside the shipped scenes (config/scenes/).
#include "covtrack/scene/scene.hpp"
#include "covtrack/scene/scene_graph.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace covtrack;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fuzz::Input input({data, size});
  const auto scene = scene::parse_scene(input.rest_text(), "fuzz.toml", COVTRACK_SOURCE_DIR "/config/scenes");
  if (!scene) {
    FUZZ_CHECK(!scene.error().message.empty());
    return 0;
  }
  client::TransformGraph graph;
  if (const auto added = scene::add_scene_transforms(*scene, graph, 1'000'000); !added)
    FUZZ_CHECK(!added.error().message.empty());
  if (const auto hulls = scene::hull_objects(*scene)) {
    for (const auto& object : *hulls)
      for (const Vec3& v : object.hull_vertices_m) FUZZ_CHECK(v.allFinite());
  }
  for (const auto& t : scene->transforms) {
    FUZZ_CHECK(t.T_parent_child.matrix().allFinite());
    FUZZ_CHECK(scene::scripted_value(t, 0.5).T_parent_child.matrix().allFinite());
  }
  return 0;
}
