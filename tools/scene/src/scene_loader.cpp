#include <filesystem>
#include <numbers>

#include <fmt/format.h>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/covariance_keys.hpp"
#include "covtrack/scene/scene.hpp"

namespace covtrack::scene {
namespace {

const TableSpec& top_spec() {
  static const TableSpec s{"(top level)", "covtrack regions",
                           {{"camera", ValueType::Table, "", "", "the camera: [camera]"},
                            {"transform", ValueType::TableArray, "", "[]",
                             "the frame tree: one [[transform]] per edge"},
                            {"object", ValueType::TableArray, "", "[]",
                             "objects to register: one [[object]] each"}}};
  return s;
}

const TableSpec& camera_spec() {
  static const TableSpec s{"camera", "covtrack regions",
                           {{"frame", ValueType::String, "", "", "the camera's frame in the tree"},
                            {"calibration", ValueType::String, "", "",
                             "OpenCV calibration file (YAML/XML), relative to the scene file"},
                            {"confidence", ValueType::Float, "", "0.95",
                             "probability inside each error ellipse", 0.5, 0.9999}}};
  return s;
}

const TableSpec& transform_spec() {
  static const TableSpec s = [] {
    TableSpec t{"transform[]", "covtrack regions",
                {{"parent", ValueType::String, "", "", "parent frame"},
                 {"child", ValueType::String, "", "", "child frame (has exactly one parent)"},
                 {"position_m", ValueType::FloatArray, "m", "[0, 0, 0]",
                  "child origin in the parent frame", -1e6, 1e6, 3},
                 {"rotation_rpy_deg", ValueType::FloatArray, "deg", "[0, 0, 0]",
                  "roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll); or orientation_wxyz", -360, 360, 3},
                 {"orientation_wxyz", ValueType::FloatArray, "", "",
                  "unit quaternion w x y z; instead of rotation_rpy_deg", -1, 1, 4},
                 {"stream", ValueType::String, "", "",
                  "tracked edge: the device/sensor stream that updates it"},
                 {"max_speed_mps", ValueType::Float, "m/s", "0",
                  "tracked edge: bound on linear speed, grows the covariance with report age", 0, 1e3},
                 {"max_angular_speed_radps", ValueType::Float, "rad/s", "0",
                  "tracked edge: bound on angular speed", 0, 1e3}}};
    const auto cov = covariance_keys();
    t.keys.insert(t.keys.end(), cov.begin(), cov.end());
    return t;
  }();
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
                             "x y z of each vertex, flattened; instead of box_m", -1e6, 1e6}}};
  return s;
}

Pose read_pose(TableReader& r) {
  Pose T = Pose::Identity();
  T.translation() = r.vec3("position_m");
  if (r.has("orientation_wxyz") && r.has("rotation_rpy_deg")) {
    r.error("orientation_wxyz", "give orientation_wxyz or rotation_rpy_deg, not both");
  } else if (r.has("orientation_wxyz")) {
    const auto q = r.numbers("orientation_wxyz");
    if (q.size() == 4) {
      const Eigen::Quaterniond quat(q[0], q[1], q[2], q[3]);
      if (std::abs(quat.norm() - 1) > 1e-6)
        r.error("orientation_wxyz", fmt::format("norm is {}, not 1", quat.norm()));
      else
        T.linear() = quat.toRotationMatrix();
    }
  } else if (r.has("rotation_rpy_deg")) {
    const Vec3 rpy = r.vec3("rotation_rpy_deg") * std::numbers::pi / 180;
    T.linear() = (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                  Eigen::AngleAxisd(rpy.x(), Vec3::UnitX())).toRotationMatrix();
  }
  return T;
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

std::vector<Vec3> box(const Vec3& size, const Vec3& center) {
  std::vector<Vec3> out;
  for (int i = 0; i < 8; ++i)
    out.push_back(center + 0.5 * Vec3((i & 1) ? size.x() : -size.x(), (i & 2) ? size.y() : -size.y(),
                                      (i & 4) ? size.z() : -size.z()));
  return out;
}

SceneObject read_object(TableReader& r) {
  SceneObject o;
  o.name = r.string("name");
  o.frame = r.string("frame");
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
  return o;
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
  }
  const auto objects = top.tables("object");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    TableReader r(*objects[i], fmt::format("object[{}]", i), object_spec(), source, errors);
    scene.objects.push_back(read_object(r));
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
         schema_markdown({&top_spec(), &camera_spec(), &transform_spec(), &object_spec()});
}

}  // namespace covtrack::scene
