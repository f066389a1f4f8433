#pragma once
// A scene file (config/scenes/*.toml, documented in config/scene_schema.md): frames joined
// by uncertain transforms, some bound to tracker streams; a camera; objects to register.
// It answers "what registration error will my setup have?" before anyone builds it.
#include <optional>
#include <string>
#include <vector>

#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::scene {

struct SceneTransform {
  std::string parent;
  std::string child;
  Pose T_parent_child = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // BODY; for a tracked edge, its value until a report
  std::optional<StreamId> stream;  // tracked edge: bound to this device/sensor stream
  double max_speed_mps = 0;        // tracked edge: motion bound for staleness growth
  double max_angular_speed_radps = 0;
};

struct SceneObject {
  std::string name;
  std::string frame;
  std::vector<Vec3> vertices_m;  // in the object's frame
};

struct SceneCamera {
  std::string frame;
  std::string calibration_path;  // resolved against the scene file's folder
  double confidence = 0.95;
};

struct Scene {
  std::vector<SceneTransform> transforms;
  SceneCamera camera;
  std::vector<SceneObject> objects;
};

// Every problem at once, each as file:line:column: key.path: what is wrong.
Result<Scene> load_scene(const std::string& path);
Result<Scene> parse_scene(std::string_view toml_text, const std::string& source_name,
                          const std::string& base_dir);

// config/scene_schema.md
std::string scene_schema_markdown();

}  // namespace covtrack::scene
