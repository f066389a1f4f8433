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

// One point of an offline script for a tracked edge: what its tracker reports at time
// t_s of the scene's clock (values between keyframes are interpolated linearly).
struct Keyframe {
  double t_s = 0;
  Vec3 position_m = Vec3::Zero();  // the edge's position_m unless the keyframe sets it
  double sigma_scale = 1;          // multiplies the edge's sigmas (covariance by its square)
  bool lost = false;               // the tracker reports LOST from t_s to the next keyframe
};

struct SceneTransform {
  std::string parent;
  std::string child;
  Pose T_parent_child = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // BODY; for a tracked edge, its value until a report
  std::optional<StreamId> stream;  // tracked edge: bound to this device/sensor stream
  double max_speed_mps = 0;        // tracked edge: motion bound for staleness growth
  double max_angular_speed_radps = 0;
  // Offline only (no --live, no --log): the reports its tracker would send, repeated with
  // the period of the last keyframe's t_s. Empty: the edge's fixed value.
  std::vector<Keyframe> keyframes;
  bool lost = false;  // a scripted value: the report at this time is LOST
};

// How a fused frame combines its paths (client::TransformGraph::add_fused_frame).
enum class FusionCombiner { joint, covariance_intersection, smallest };

// One physical frame estimated along several paths: each via frame stands for it.
struct SceneFusion {
  std::string frame;
  std::string parent;
  std::vector<std::string> via;
  FusionCombiner combiner = FusionCombiner::joint;
};

// Level-of-Error augmentations `covtrack view` can draw (dissertation 5.6.2,
// docs/background.md), from the one that relies most on registration to the one that
// relies on it least.
enum class Augmentation { outline, region, label };
const char* to_string(Augmentation a);

struct SceneObject {
  std::string name;
  std::string frame;
  std::vector<Vec3> vertices_m;  // in the object's frame
  // Level of Error: n ascending assessment thresholds (px) pick one of n + 1
  // augmentations; empty: always the first.
  std::vector<double> level_of_error_px;
  double level_of_error_margin_px = 1;
  std::vector<Augmentation> augmentations{Augmentation::outline};
  std::string model_path;  // `covtrack ar`'s 3-D model, resolved against the scene's folder; empty: its hull
};

enum class Likelihood { area, distance };

// A tracked pointer (dissertation chapter 6): a point of a frame, projected with its error,
// that selects among the objects.
struct ScenePointer {
  std::string frame;
  Vec3 tip_m = Vec3::Zero();
  Likelihood likelihood = Likelihood::area;
};

struct SceneCamera {
  std::string frame;
  std::string calibration_path;  // resolved against the scene file's folder
  double confidence = 0.95;
};

struct Scene {
  std::vector<SceneTransform> transforms;
  std::vector<SceneFusion> fused;  // added after every transform, in order
  SceneCamera camera;
  std::vector<SceneObject> objects;
  std::optional<ScenePointer> pointer;
};

// A scripted transform's value at scene_time_s: position and sigma scale interpolated
// between its keyframes, repeating with the last keyframe's period; the transform itself
// when it has no keyframes.
SceneTransform scripted_value(const SceneTransform& t, double scene_time_s);

// Every problem at once, each as file:line:column: key.path: what is wrong.
Result<Scene> load_scene(const std::string& path);
Result<Scene> parse_scene(std::string_view toml_text, const std::string& source_name,
                          const std::string& base_dir);

// config/scene_schema.md
std::string scene_schema_markdown();

}  // namespace covtrack::scene
