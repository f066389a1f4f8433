#include "covtrack/scene/scene_graph.hpp"

#include <fmt/format.h>

#include "covtrack/client/object_hull.hpp"

namespace covtrack::scene {

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
    client::TrackedTransform report;
    report.stream = *t.stream;
    report.parent_frame = t.parent;
    report.child_frame = t.child;
    report.T_parent_child = t.T_parent_child;
    report.covariance = t.covariance;
    report.status = TrackingStatus::Ok;
    report.measurement_time_us = report.publish_time_us = report.receive_time_us = *reports_at_us;
    if (auto r = graph.update(t.child, report); !r) return where(r.error());
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
