#include "covtrack/scene/scene_graph.hpp"

#include <fmt/format.h>

#include "covtrack/client/object_hull.hpp"

namespace covtrack::scene {

namespace {
client::TrackedTransform report_of(const SceneTransform& t, std::int64_t measured_us) {
  client::TrackedTransform report;
  report.stream = *t.stream;
  report.parent_frame = t.parent;
  report.child_frame = t.child;
  report.T_parent_child = t.T_parent_child;
  report.covariance = t.lost ? lost_covariance() : t.covariance;
  report.status = t.lost ? TrackingStatus::Lost : TrackingStatus::Ok;
  report.measurement_time_us = report.publish_time_us = report.receive_time_us = measured_us;
  return report;
}
}  // namespace

Result<void> add_scene_transforms(const Scene& scene, client::TransformGraph& graph,
                                  std::optional<std::int64_t> reports_at_us) {
  for (const SceneTransform& t : scene.transforms) {
    const auto where = [&](const Error& e) {
      return fail(fmt::format("transform {} -> {}: {}", t.parent, t.child, e.message));
    };
    if (!t.stream) {
      if (auto r = graph.add_static_edge(t.parent, t.child, t.T_parent_child, t.covariance); !r)
        return where(r.error());
      continue;
    }
    const client::MotionBound motion{t.max_speed_mps, t.max_angular_speed_radps};
    if (auto r = graph.add_tracked_edge(t.parent, t.child, *t.stream, motion); !r)
      return where(r.error());
    if (!reports_at_us) continue;
    if (auto r = graph.update(t.child, report_of(scripted_value(t, 0), *reports_at_us)); !r)
      return where(r.error());
  }
  for (const SceneFusion& f : scene.fused) {
    std::optional<client::Combiner> combiner;
    if (f.combiner == FusionCombiner::covariance_intersection) combiner = client::Combiner::covariance_intersection();
    if (f.combiner == FusionCombiner::smallest) combiner = client::Combiner::smallest();
    if (auto r = graph.add_fused_frame(f.parent, f.frame, f.via, std::move(combiner)); !r)
      return fail(fmt::format("fused {} -> {}: {}", f.parent, f.frame, r.error().message));
  }
  return {};
}

Result<void> report_keyframes(const Scene& scene, client::TransformGraph& graph,
                              double scene_time_s, std::int64_t now_us) {
  for (const SceneTransform& t : scene.transforms) {
    if (t.keyframes.empty()) continue;
    if (auto r = graph.update(t.child, report_of(scripted_value(t, scene_time_s), now_us)); !r)
      return fail(fmt::format("transform {} -> {}: {}", t.parent, t.child, r.error().message));
  }
  return {};
}

Result<std::vector<HullObject>> hull_objects(const Scene& scene) {
  std::vector<HullObject> out;
  for (const SceneObject& o : scene.objects) {
    const auto ids = client::convex_hull_indices_3d(o.vertices_m);
    if (!ids) return fail(fmt::format("object {}: {}", o.name, ids.error().message));
    HullObject h{o.name, o.frame, {}};
    for (int i : *ids) h.hull_vertices_m.push_back(o.vertices_m[i]);
    out.push_back(std::move(h));
  }
  return out;
}

}  // namespace covtrack::scene
