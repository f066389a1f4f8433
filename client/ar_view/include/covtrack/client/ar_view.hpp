#pragma once
// The per-frame AR API: for one camera, everything a renderer needs to draw a frame's
// augmentations honestly, in one call and as plain data (no rendering types):
//   - each object's pose in the camera and its BODY covariance (from the transform graph),
//   - its screen regions and assessment (regions.hpp),
//   - its Level-of-Error level (level_of_error.hpp; the hysteresis runs across calls),
//   - where its label goes (label_placer.hpp).
// A renderer maps each level to its own augmentation (a subgraph, a style) and draws; the
// 2-D viewer (`covtrack view`) is one such renderer.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "covtrack/client/camera.hpp"
#include "covtrack/client/label_placer.hpp"
#include "covtrack/client/level_of_error.hpp"
#include "covtrack/client/regions.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::client {

struct ArObject {
  std::string name;
  std::string frame;                  // its frame in the transform graph
  std::vector<Vec3> vertices_object;  // in `frame`; its 3-D hull's vertices are enough
  // Ascending thresholds on the assessment (px): n thresholds choose among n + 1 levels.
  std::vector<double> level_of_error_px;
  double level_of_error_margin_px = 1;
  // The levels whose augmentation does not rely on registration: there the label goes to
  // the corner list instead of next to the object. Empty: never.
  std::vector<bool> label_listed_at_level;
};

struct ArObjectFrame {
  UncertainPose T_camera_object;  // unbounded when a tracker on its path is LOST
  ObjectRegions regions;          // vertices, outer and inner regions, assessment, flags
  int level = 0;                  // Level of Error, 0 ... thresholds
  PlacedLabel label;
};

struct ArFrame {
  std::int64_t time_us = 0;
  std::vector<ArObjectFrame> objects;  // one per ArObject, in the same order
};

struct ArViewOptions {
  ObjectRegionOptions regions;
  LabelPlacerOptions labels;  // set labels.screen to the area the renderer draws into
  // The label box (px) of an object in this frame, for renderers whose label text depends
  // on it (its assessment, say). Unset: LabelRequest's default size.
  std::function<Vec2(std::size_t object, const ArObjectFrame&)> label_box;
};

class ArView {
 public:
  // Fails naming the object whose Level-of-Error thresholds are invalid.
  static Result<ArView> create(Camera camera, std::string camera_frame, std::vector<ArObject> objects,
                               ArViewOptions options = {});

  // Computes the frame at time_us. Fails naming the object whose frame is not connected
  // to the camera's; the last good frame is kept then.
  Result<void> update(const TransformGraph& graph, std::int64_t time_us);
  const ArFrame& frame() const { return frame_; }
  const std::vector<ArObject>& objects() const { return objects_; }

 private:
  Result<UncertainPose> query(const TransformGraph& graph, std::size_t object, std::int64_t time_us);
  ArView(Camera camera, std::string camera_frame, std::vector<ArObject> objects,
         std::vector<LevelOfError> levels, ArViewOptions options);

  Camera camera_;
  std::string camera_frame_;
  std::vector<ArObject> objects_;
  std::vector<LevelOfError> levels_;  // one per object
  ArViewOptions options_;
  ArFrame frame_, next_;  // the frame handed out, and the one being computed
  std::vector<LabelRequest> requests_;
  // Each object's frame and the camera's, looked up in the graph last updated from.
  std::optional<TransformGraph::FrameKey> camera_key_;
  std::vector<std::optional<TransformGraph::FrameKey>> frame_keys_;
  LabelPlacer placer_;  // its memory, and that of the buffers around it, lasts across frames
  std::vector<PlacedLabel> labels_;
};

}  // namespace covtrack::client
