#include <limits>

#include "covtrack/client/regions.hpp"

namespace covtrack::client {

ObjectRegions compute_object_regions(const Camera& camera, const UncertainPose& T_camera_object,
                                     std::span<const Vec3> vertices_object,
                                     const ObjectRegionOptions& o) {
  ObjectRegions r;
  r.vertices = project_vertices(camera, T_camera_object, vertices_object, o.projection);
  r.valid = !r.vertices.empty();
  for (const ProjectedVertex& v : r.vertices) {
    r.flags |= v.flags;
    r.valid = r.valid && v.flags.usable();
  }
  if (!r.valid) {
    r.assessment = std::numeric_limits<double>::infinity();
    return r;
  }

  std::vector<Vec2> means;
  means.reserve(r.vertices.size());
  for (const ProjectedVertex& v : r.vertices) means.push_back(v.mean_px);
  r.hull = convex_hull_indices(means);
  std::vector<ProjectedVertex> hull;
  hull.reserve(r.hull.size());
  for (int i : r.hull) hull.push_back(r.vertices[i]);

  // Every vertex's ellipse goes into the outer region, not only the hull's: a vertex just
  // inside the mean hull can still stick out once perturbed. The inner region needs only
  // the hull (a subset of the true vertices spans less, so it stays conservative).
  r.outer = expand_region(r.vertices, o.regions);
  r.inner = contract_region(hull, o.regions);
  r.assessment = assess(o.assessment, hull);
  return r;
}

}  // namespace covtrack::client
