#include "covtrack/client/ar_view.hpp"

#include <utility>

namespace covtrack::client {

Result<ArView> ArView::create(Camera camera, std::string camera_frame, std::vector<ArObject> objects,
                              ArViewOptions options) {
  std::vector<LevelOfError> levels;
  for (const ArObject& o : objects) {
    auto level = LevelOfError::create(o.level_of_error_px, o.level_of_error_margin_px);
    if (!level) return fail("object " + o.name + ": " + level.error().message);
    levels.push_back(std::move(*level));
  }
  return ArView(std::move(camera), std::move(camera_frame), std::move(objects), std::move(levels),
                std::move(options));
}

ArView::ArView(Camera camera, std::string camera_frame, std::vector<ArObject> objects,
               std::vector<LevelOfError> levels, ArViewOptions options)
    : camera_(std::move(camera)),
      camera_frame_(std::move(camera_frame)),
      objects_(std::move(objects)),
      levels_(std::move(levels)),
      options_(std::move(options)) {}

namespace {
bool label_listed(const ArObject& o, int level) {
  const auto l = static_cast<std::size_t>(level);
  return l < o.label_listed_at_level.size() && o.label_listed_at_level[l];
}
}  // namespace

Result<UncertainPose> ArView::query(const TransformGraph& graph, std::size_t object, std::int64_t time_us) {
  // Names are looked up once per graph (a key names its graph); a frame the graph does not
  // have yet is looked up again each frame, and queried by name so that the error is the
  // graph's own.
  const auto keyed = [&](std::optional<TransformGraph::FrameKey>& key, const std::string& frame) {
    if (!key || key->graph != graph.id()) key = graph.key(frame);
    return key.has_value();
  };
  if (keyed(camera_key_, camera_frame_) && keyed(frame_keys_[object], objects_[object].frame))
    return graph.query(*camera_key_, *frame_keys_[object], time_us);
  return graph.query(camera_frame_, objects_[object].frame, time_us);
}

Result<void> ArView::update(const TransformGraph& graph, std::int64_t time_us) {
  const std::size_t n = objects_.size();
  next_.time_us = time_us;
  frame_keys_.resize(n);
  next_.objects.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const ArObject& o = objects_[i];
    auto T = query(graph, i, time_us);
    if (!T) return fail("object " + o.name + ": " + T.error().message);
    ArObjectFrame& f = next_.objects[i];
    f.T_camera_object = *T;
    compute_object_regions(camera_, *T, o.vertices_object, options_.regions, f.regions);
  }
  // Only a complete frame moves the Level-of-Error switches (their hysteresis is state).
  requests_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    ArObjectFrame& f = next_.objects[i];
    f.level = levels_[i].update(f.regions.assessment);
    LabelRequest& r = requests_[i];
    r.size_px = options_.label_box ? options_.label_box(i, f) : LabelRequest{}.size_px;
    // The regions are lent to the placer and taken back: no copy per object and frame.
    r.inner.clear();
    r.outer.clear();
    if (!label_listed(objects_[i], f.level)) {
      std::swap(r.inner, f.regions.inner);
      std::swap(r.outer, f.regions.outer);
    }
  }
  placer_.place(requests_, options_.labels, labels_);
  for (std::size_t i = 0; i < n; ++i) {
    ArObjectFrame& f = next_.objects[i];
    f.label = labels_[i];
    if (!label_listed(objects_[i], f.level)) {
      std::swap(requests_[i].inner, f.regions.inner);
      std::swap(requests_[i].outer, f.regions.outer);
    }
  }
  std::swap(frame_, next_);
  return {};
}

}  // namespace covtrack::client
