#pragma once
// A scene's objects through its camera: the regions `covtrack regions` prints and
// `covtrack view` draws. The scene is loaded once (RegionsModel); regions are computed
// per frame from a transform graph at a time.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "covtrack/client/regions.hpp"
#include "covtrack/client/selection.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/scene/scene_graph.hpp"

namespace covtrack::cli {

struct RegionsModel {
  std::string scene_path;
  scene::Scene scene;
  client::Camera camera;
  double confidence = 0.95;
  std::vector<scene::HullObject> objects;  // each object's 3-D hull, computed once
};

// confidence 0 takes the scene's. Errors name the scene file (and line, for its syntax).
Result<RegionsModel> load_regions_model(const std::string& scene_path, double confidence);

struct RegionsReport {
  struct Object {
    std::string name;
    std::string frame;
    std::vector<Vec3> hull_vertices_m;  // same order as regions.vertices
    client::ObjectRegions regions;
  };
  client::Camera camera;
  std::string camera_frame;
  double confidence = 0.95;
  std::vector<Object> objects;
  // The scene's pointer tip on the screen, with its error (when the scene has a pointer).
  std::optional<client::ProjectedVertex> pointer_tip;
};

// The names of the flags that are set ("behind_camera", ...), as `covtrack regions` prints them.
std::vector<std::string> flag_names(const client::ProjectionFlags& flags);

// The regions of every object at time_us. Fails naming the object (not the file) if its
// frame is not connected to the camera's.
Result<RegionsReport> compute_regions(const RegionsModel& model, const client::TransformGraph& graph,
                                      std::int64_t time_us, client::ProjectionMethod method);

// The objects as selection sees them: where each can be on the screen (its outer region).
std::vector<client::Selectable> selectables_of(const RegionsReport& report);

}  // namespace covtrack::cli
