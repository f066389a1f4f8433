#include <cmath>
#include <limits>

#include "covtrack/client/regions.hpp"
#include "regions_from_tangents.hpp"

namespace covtrack::client {
namespace {
// Every coordinate finite, in one sum (a sum that overflows flags numbers near the
// largest double too): checked for every object of every frame, so summed as one array,
// which Eigen does in vector registers.
bool finite_sum(const Polygon& polygon) {
  if (polygon.empty()) return true;
  return std::isfinite(Eigen::Map<const Eigen::VectorXd>(polygon.data()->data(), 2 * polygon.size()).sum());
}

// An object whose regions mean nothing: none, and the assessment that says so.
void no_regions(ObjectRegions& r) {
  r.valid = false;
  r.outer.clear();
  r.inner.clear();
  r.hull.clear();
  r.outer_scale = 0;
  r.assessment = std::numeric_limits<double>::infinity();
}
}  // namespace

void compute_object_regions(const Camera& camera, const UncertainPose& T_camera_object,
                            std::span<const Vec3> vertices_object, const ObjectRegionOptions& o,
                            ObjectRegions& r) {
  project_vertices(camera, T_camera_object, vertices_object, o.projection, r.vertices);
  r.flags = {};
  r.valid = !r.vertices.empty();
  for (const ProjectedVertex& v : r.vertices) {
    r.flags |= v.flags;
    r.valid = r.valid && v.flags.usable();
  }
  if (!r.valid) return no_regions(r);

  // Scratch kept per thread: a frame of many objects allocates nothing. The hull's buffer
  // is taken out of its pool while in use, because the assessment runs user code that
  // may compute regions itself (it then finds the pool empty and allocates its own).
  thread_local std::vector<Vec2> means;
  thread_local std::vector<ProjectedVertex> hull_pool;
  std::vector<ProjectedVertex> hull = std::move(hull_pool);
  means.clear();
  for (const ProjectedVertex& v : r.vertices) means.push_back(v.mean_px);
  convex_hull_indices(means, r.hull);
  hull.clear();
  for (int i : r.hull) hull.push_back(r.vertices[i]);

  // Every vertex's ellipse goes into the outer region, not only the hull's: a vertex just
  // inside the mean hull can still stick out once perturbed. The inner region needs only
  // the hull (a subset of the true vertices spans less, so it stays conservative).
  // Both regions start from the hull edges' tangents, both sides solved in one block
  // (region_tangents.hpp).
  thread_local std::vector<TangentLine> inner_lines, outer_lines;
  outer_lines.clear();  // stays empty without the shortcut
  // The inner region at one vertex's scale, the outer at the whole object's.
  const double s2 = std::pow(confidence_scale(o.regions.confidence), 2);
  const double outer_s2 = o.regions.whole_object
                              ? whole_object_scale2(camera, T_camera_object, vertices_object, r.vertices,
                                                    r.hull, o.regions.confidence)
                              : s2;
  r.outer_scale = std::sqrt(outer_s2);
  hull_tangents(hull.size(), [&](std::size_t i) -> const ProjectedVertex& { return hull[i]; }, s2, outer_s2,
                &inner_lines, o.regions.outer_by_arcs ? &outer_lines : nullptr);
  expand_region(r.vertices, r.hull, outer_lines, outer_s2, o.regions, r.outer);
  contract_region(hull, inner_lines, r.inner);
  r.assessment = assess(o.assessment, hull);
  hull_pool = std::move(hull);
  // Finite vertices whose regions overflowed (a pixel covariance near the largest double):
  // no regions, flagged as a non-finite input is.
  if (!(finite_sum(r.outer) && finite_sum(r.inner) && std::isfinite(r.outer_scale))) {
    r.flags.not_finite = true;
    no_regions(r);
  }
}

ObjectRegions compute_object_regions(const Camera& camera, const UncertainPose& T_camera_object,
                                     std::span<const Vec3> vertices_object,
                                     const ObjectRegionOptions& o) {
  ObjectRegions r;
  compute_object_regions(camera, T_camera_object, vertices_object, o, r);
  return r;
}

}  // namespace covtrack::client
