#include <cmath>
#include <limits>

#include "covtrack/client/convex_polygon.hpp"
#include "covtrack/client/selection.hpp"

namespace covtrack::client {

Pointer pointer_with_covariance(const Vec2& position, const Mat2& covariance, double confidence,
                                int sides) {
  Pointer p{position, {}, !(position.allFinite() && covariance.allFinite())};
  if (!p.lost)
    p.region = circumscribed_ellipse_polygon(position, covariance, confidence_scale(confidence),
                                             sides);
  return p;
}

Pointer pointer_from_projection(const ProjectedVertex& tip, double confidence, int sides) {
  if (!tip.flags.usable()) return Pointer{tip.mean_px, {}, true};
  return pointer_with_covariance(tip.mean_px, tip.covariance_px2, confidence, sides);
}

double pointer_error_px(const Pointer& pointer) {
  if (pointer.lost || !pointer.position_px.allFinite())
    return std::numeric_limits<double>::infinity();
  for (const Vec2& v : pointer.region)
    if (!v.allFinite()) return std::numeric_limits<double>::infinity();
  return polygon_radius(pointer.region, pointer.position_px);
}

std::vector<double> likelihoods_by_area(const Pointer& pointer, std::span<const Selectable> objects) {
  std::vector<double> out(objects.size(), 0.0);
  if (pointer.lost) return out;
  const bool has_area = is_usable_polygon(pointer.region) && polygon_area(pointer.region) > 0;
  const double pointer_area = has_area ? polygon_area(pointer.region) : 0;
  const Box pointer_bounds = bounding_box(pointer.region);
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const Polygon& region = objects[i].region;
    if (!is_usable_polygon(region)) continue;
    if (!has_area) {
      out[i] = pointer.position_px.allFinite() && polygon_contains(region, pointer.position_px);
      continue;
    }
    // Most objects are nowhere near the pointer: skip the intersection for them.
    if (!boxes_overlap(pointer_bounds, bounding_box(region))) continue;
    const double shared = polygon_area(intersect_convex(pointer.region, region));
    out[i] = std::clamp(shared / pointer_area, 0.0, 1.0);
  }
  return out;
}

std::vector<double> likelihoods_by_distance(const Pointer& pointer,
                                            std::span<const Selectable> objects) {
  std::vector<double> out(objects.size(), 0.0);
  if (pointer.lost || !pointer.position_px.allFinite()) return out;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const Polygon& region = objects[i].region;
    if (!is_usable_polygon(region)) continue;
    const Vec2 center = polygon_centroid(region);
    const double radius = polygon_radius(region, center);
    if (radius <= 0) continue;
    out[i] = std::max(0.0, 1.0 - (pointer.position_px - center).norm() / radius);
  }
  return out;
}

Selectable selectable_of(const ObjectRegions& regions) {
  Selectable s{regions.outer, 0};
  for (const ProjectedVertex& v : regions.vertices) s.depth_m += v.depth_m / static_cast<double>(regions.vertices.size());
  return s;
}

}  // namespace covtrack::client
