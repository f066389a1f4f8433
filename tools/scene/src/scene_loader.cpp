#include <algorithm>
#include <filesystem>
#include <functional>

#include <fmt/format.h>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/covariance_keys.hpp"
#include "covtrack/devices/pose_keys.hpp"
#include "covtrack/scene/scene.hpp"
#include "covtrack/scene/transform_table.hpp"

namespace covtrack::scene {
namespace {

const TableSpec& top_spec() {
  static const TableSpec s{"(top level)", "covtrack regions",
                           {{"camera", ValueType::Table, "", "", "the camera: [camera]"},
                            {"transform", ValueType::TableArray, "", "[]",
                             "the frame tree: one [[transform]] per edge"},
                            {"transform_tables", ValueType::StringArray, "", "[]",
                             "more static edges, in bulk: CSV files relative to the scene file "
                             "(see \"Transform tables\" below)"},
                            {"fused", ValueType::TableArray, "", "[]",
                             "frames estimated along several paths of the tree: one [[fused]] each"},
                            {"object", ValueType::TableArray, "", "[]",
                             "objects to register: one [[object]] each"},
                            {"pointer", ValueType::Table, "", "(none)",
                             "a tracked pointer that selects objects: [pointer]"}}};
  return s;
}

const TableSpec& camera_spec() {
  static const TableSpec s{"camera", "covtrack regions",
                           {{"frame", ValueType::String, "", "", "the camera's frame in the tree"},
                            {"calibration", ValueType::String, "", "",
                             "camera calibration: OpenCV (YAML/XML) or ROS camera_info YAML, relative to the scene file"},
                            {"confidence", ValueType::Float, "", "0.95",
                             "probability inside each error ellipse", 0.5, 0.9999}}};
  return s;
}

const TableSpec& transform_spec() {
  static const TableSpec s = [] {
    TableSpec t{"transform[]", "covtrack regions",
                {{"parent", ValueType::String, "", "", "parent frame"},
                 {"child", ValueType::String, "", "", "child frame (has exactly one parent)"},
                 {"stream", ValueType::String, "", "",
                  "tracked edge: the device/sensor stream that updates it"},
                 {"max_speed_mps", ValueType::Float, "m/s", "0",
                  "tracked edge: bound on linear speed, grows the covariance with report age", 0, 1e3},
                 {"max_angular_speed_radps", ValueType::Float, "rad/s", "0",
                  "tracked edge: bound on angular speed", 0, 1e3},
                 {"keyframe", ValueType::TableArray, "", "[]",
                  "tracked edge, offline: scripted reports, [[transform.keyframe]]"}}};
    const auto pose = pose_keys();  // after parent and child, as the schema lists them
    t.keys.insert(t.keys.begin() + 2, pose.begin(), pose.end());
    const auto cov = covariance_keys();
    t.keys.insert(t.keys.end(), cov.begin(), cov.end());
    return t;
  }();
  return s;
}

const TableSpec& fused_spec() {
  static const TableSpec s{
      "fused[]", "covtrack regions",
      {{"frame", ValueType::String, "", "", "the fused frame (new, or the root of a tree of its own)"},
       {"parent", ValueType::String, "", "", "the frame it is estimated relative to"},
       {"via", ValueType::StringArray, "", "",
        "frames that each stand for the same physical frame, reached along another path"},
       {"combiner", ValueType::String, "", "joint",
        "joint (least squares with the paths' exact correlation), covariance_intersection "
        "(no correlation assumed) or smallest (the path with the smallest position covariance)"}}};
  return s;
}

const TableSpec& keyframe_spec() {
  static const TableSpec s{
      "transform[].keyframe[]", "covtrack view (offline)",
      {{"t_s", ValueType::Float, "s", "",
        "scene time; the first is 0, then strictly ascending; the last is the loop period", 0, 1e6},
       {"position_m", ValueType::FloatArray, "m", "the transform's",
        "child origin in the parent frame at t_s", -1e6, 1e6, 3},
       {"sigma_scale", ValueType::Float, "", "1",
        "multiplies the transform's sigmas at t_s (its covariance by the square)", 0, 1e4},
       {"lost", ValueType::Boolean, "", "false",
        "the tracker reports LOST from t_s until the next keyframe (its last pose, infinitely uncertain)"}}};
  return s;
}

const TableSpec& pointer_spec() {
  static const TableSpec s{
      "pointer", "covtrack view",
      {{"frame", ValueType::String, "", "", "the pointer's frame in the tree"},
       {"tip_m", ValueType::FloatArray, "m", "[0, 0, 0]", "the pointing point in that frame", -1e6, 1e6, 3},
       {"likelihood", ValueType::String, "", "area",
        "area (of the pointer's region on the object's) or distance (to its centre)"}}};
  return s;
}

const TableSpec& object_spec() {
  static const TableSpec s{"object[]", "covtrack regions",
                           {{"name", ValueType::String, "", "", "the object's name"},
                            {"frame", ValueType::String, "", "", "the frame its vertices are in"},
                            {"box_m", ValueType::FloatArray, "m", "",
                             "size x y z of a box centred on box_center_m; or vertices_m", 0, 1e4, 3},
                            {"box_center_m", ValueType::FloatArray, "m", "[0, 0, 0]",
                             "centre of the box in the object's frame", -1e6, 1e6, 3},
                            {"vertices_m", ValueType::FloatArray, "m", "",
                             "x y z of each vertex, flattened; instead of box_m", -1e6, 1e6},
                            {"level_of_error_px", ValueType::FloatArray, "px", "[]",
                             "ascending assessment thresholds between the augmentations", 0, 1e6},
                            {"level_of_error_margin_px", ValueType::Float, "px", "1",
                             "hysteresis: a level is left only this far below its threshold", 0, 1e6},
                            {"augmentations", ValueType::StringArray, "", "[\"outline\"]",
                             "one per level: outline, region or label (one more than thresholds)"},
                            {"model", ValueType::String, "", "(its hull)",
                             "covtrack ar: a 3-D model of the object (any format OpenSceneGraph reads), in its "
                             "frame and in metres, relative to the scene file"}}};
  return s;
}

SceneTransform read_transform(TableReader& r) {
  SceneTransform t;
  t.parent = r.string("parent");
  t.child = r.string("child");
  if (!t.parent.empty() && t.parent == t.child) r.error("child", "a frame cannot be its own parent");
  t.T_parent_child = read_pose(r);
  t.covariance = read_covariance(r);
  if (r.has("stream")) {
    const std::string s = r.string("stream");
    const auto slash = s.find('/');
    StreamId id{s.substr(0, slash), slash == std::string::npos ? "" : s.substr(slash + 1)};
    if (!is_valid_name(id.device) || !is_valid_name(id.sensor))
      r.error("stream", fmt::format("'{}' is not device/sensor", s));
    t.stream = id;
  }
  t.max_speed_mps = r.number("max_speed_mps", 0);
  t.max_angular_speed_radps = r.number("max_angular_speed_radps", 0);
  return t;
}

void read_keyframes(TableReader& r, SceneTransform& t) {
  const auto tables = r.tables("keyframe");
  if (!tables.empty() && !t.stream)
    r.error("keyframe", "keyframes script a tracker's reports: the transform needs a stream");
  for (std::size_t i = 0; i < tables.size(); ++i) {
    TableReader k(*tables[i], r.path(fmt::format("keyframe[{}]", i)), keyframe_spec(), r.file(), r.errors());
    Keyframe f{k.number("t_s"), k.vec3("position_m", t.T_parent_child.translation()), k.number("sigma_scale", 1),
               k.boolean("lost", false)};
    if (i == 0 && f.t_s != 0) k.error("t_s", "the first keyframe is at 0");
    if (i > 0 && f.t_s <= t.keyframes.back().t_s) k.error("t_s", "keyframes must be in ascending time");
    t.keyframes.push_back(f);
  }
}

SceneFusion read_fusion(TableReader& r) {
  SceneFusion f;
  f.frame = r.string("frame");
  f.parent = r.string("parent");
  f.via = r.strings("via");
  if (r.has("via") && f.via.empty()) r.error("via", "names no frame");
  const std::string combiner = r.choice("combiner", {"joint", "covariance_intersection", "smallest"}, "joint");
  f.combiner = combiner == "covariance_intersection" ? FusionCombiner::covariance_intersection
               : combiner == "smallest"              ? FusionCombiner::smallest
                                                     : FusionCombiner::joint;
  return f;
}

std::vector<Vec3> box(const Vec3& size, const Vec3& center) {
  std::vector<Vec3> out;
  for (int i = 0; i < 8; ++i)
    out.push_back(center + 0.5 * Vec3((i & 1) ? size.x() : -size.x(), (i & 2) ? size.y() : -size.y(),
                                      (i & 4) ? size.z() : -size.z()));
  return out;
}

SceneObject read_object(TableReader& r, const std::string& base_dir) {
  SceneObject o;
  o.name = r.string("name");
  o.frame = r.string("frame");
  if (r.has("model")) o.model_path = (std::filesystem::path(base_dir) / r.string("model")).string();
  if (r.has("box_m") == r.has("vertices_m")) {
    r.error("box_m", "give exactly one of box_m or vertices_m");
  } else if (r.has("box_m")) {
    o.vertices_m = box(r.vec3("box_m"), r.vec3("box_center_m"));
  } else {
    const auto flat = r.numbers("vertices_m");
    if (flat.size() % 3 != 0 || flat.empty())
      r.error("vertices_m", fmt::format("needs groups of 3 numbers, found {} numbers", flat.size()));
    else
      for (std::size_t i = 0; i < flat.size(); i += 3) o.vertices_m.emplace_back(flat[i], flat[i + 1], flat[i + 2]);
  }
  o.level_of_error_px = r.numbers("level_of_error_px");
  if (!std::is_sorted(o.level_of_error_px.begin(), o.level_of_error_px.end(), std::less_equal<>()))
    r.error("level_of_error_px", "thresholds must be strictly ascending");
  o.level_of_error_margin_px = r.number("level_of_error_margin_px", 1);
  if (r.has("augmentations")) {
    o.augmentations.clear();
    constexpr Augmentation kAll[] = {Augmentation::outline, Augmentation::region, Augmentation::label};
    for (const std::string& name : r.strings("augmentations")) {
      const auto* known = std::find_if(std::begin(kAll), std::end(kAll), [&](Augmentation a) { return name == to_string(a); });
      if (known == std::end(kAll)) r.error("augmentations", fmt::format("'{}' is not outline, region or label", name));
      else o.augmentations.push_back(*known);
    }
  }
  if (o.augmentations.size() != o.level_of_error_px.size() + 1)
    r.error("augmentations", fmt::format("{} thresholds need {} augmentations, found {}",
                                         o.level_of_error_px.size(), o.level_of_error_px.size() + 1,
                                         o.augmentations.size()));
  return o;
}

ScenePointer read_pointer(TableReader& r) {
  ScenePointer p;
  p.frame = r.string("frame");
  p.tip_m = r.vec3("tip_m");
  p.likelihood = r.choice("likelihood", {"area", "distance"}, "area") == "distance" ? Likelihood::distance
                                                                                     : Likelihood::area;
  return p;
}

}  // namespace

Result<Scene> parse_scene(std::string_view text, const std::string& source, const std::string& base_dir) {
  auto root = parse_toml(text, source);
  if (!root) return std::unexpected(root.error());
  ConfigErrors errors;
  TableReader top(*root, "", top_spec(), source, errors);
  Scene scene;
  if (const toml::table* cam = top.table("camera")) {
    TableReader r(*cam, "camera", camera_spec(), source, errors);
    scene.camera.frame = r.string("frame");
    const std::string calibration = r.string("calibration");
    scene.camera.calibration_path =
        calibration.empty() ? "" : (std::filesystem::path(base_dir) / calibration).string();
    scene.camera.confidence = r.number("confidence", 0.95);
  }
  const auto transforms = top.tables("transform");
  for (std::size_t i = 0; i < transforms.size(); ++i) {
    TableReader r(*transforms[i], fmt::format("transform[{}]", i), transform_spec(), source, errors);
    scene.transforms.push_back(read_transform(r));
    read_keyframes(r, scene.transforms.back());
  }
  for (const std::string& table : top.strings("transform_tables")) {
    auto rows = load_transform_table((std::filesystem::path(base_dir) / table).string());
    if (!rows) {
      top.error("transform_tables", rows.error().message);
      continue;
    }
    scene.transforms.insert(scene.transforms.end(), std::make_move_iterator(rows->begin()),
                            std::make_move_iterator(rows->end()));
  }
  const auto fused = top.tables("fused");
  for (std::size_t i = 0; i < fused.size(); ++i) {
    TableReader r(*fused[i], fmt::format("fused[{}]", i), fused_spec(), source, errors);
    scene.fused.push_back(read_fusion(r));
  }
  const auto objects = top.tables("object");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    TableReader r(*objects[i], fmt::format("object[{}]", i), object_spec(), source, errors);
    scene.objects.push_back(read_object(r, base_dir));
  }
  if (const toml::table* p = top.table("pointer")) {
    TableReader r(*p, "pointer", pointer_spec(), source, errors);
    scene.pointer = read_pointer(r);
  }
  if (!errors.empty()) return fail(errors.joined());
  return scene;
}

Result<Scene> load_scene(const std::string& path) {
  auto text = read_config_text(path);
  if (!text) return std::unexpected(text.error());
  return parse_scene(*text, path, std::filesystem::path(path).parent_path().string());
}

std::string scene_schema_markdown() {
  return "# Scene file schema\n\nRead by `covtrack regions SCENE`. Generated by "
         "`covtrack regions --print-schema`; a test keeps this file equal to its output.\n\n" +
         schema_markdown({&top_spec(), &camera_spec(), &transform_spec(), &keyframe_spec(), &fused_spec(),
                          &object_spec(), &pointer_spec()}) +
         fmt::format(
             "## Transform tables\n\n"
             "A long chain of static transforms loads faster from a CSV file named in "
             "`transform_tables` than as `[[transform]]` tables (a 100,000-link chain: "
             "`build/tests/tools/bench_scene_chain`). Lines starting with `#` and empty lines are "
             "skipped; the first other line is the header, exactly\n\n    {}\n\n"
             "and each row is one edge: parent and child frame (no comma, quote or space), the "
             "child's position in metres, roll, pitch and yaw in degrees (as `rotation_rpy_deg`), "
             "and the 1-sigma errors (as `sigma_m` and `sigma_rad`), with the same ranges as "
             "those keys. Errors name the file, line and column.\n",
             kTransformTableHeader);
}

const char* to_string(Augmentation a) {
  switch (a) {
    case Augmentation::outline: return "outline";
    case Augmentation::region: return "region";
    case Augmentation::label: return "label";
  }
  return "?";
}

}  // namespace covtrack::scene
