#include "covtrack/client/screen_box.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace covtrack::client {

Box box_at_center(const Vec2& center_px, const Vec2& size_px) {
  return {center_px - 0.5 * size_px, center_px + 0.5 * size_px};
}

Box box_at_corner(const Vec2& min_px, const Vec2& size_px) { return {min_px, min_px + size_px}; }

Polygon box_polygon(const Box& b) {
  return {b.min, Vec2(b.max.x(), b.min.y()), b.max, Vec2(b.min.x(), b.max.y())};
}

namespace {
// Projections of a point set onto an axis: [lo, hi].
template <typename Points>
void project(const Points& points, const Vec2& axis, double& lo, double& hi) {
  lo = hi = axis.dot(points[0]);
  for (const Vec2& p : points) {
    const double d = axis.dot(p);
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
}

bool separates(const std::array<Vec2, 4>& corners, const Polygon& convex, const Vec2& axis) {
  double a_lo, a_hi, b_lo, b_hi;
  project(corners, axis, a_lo, a_hi);
  project(convex, axis, b_lo, b_hi);
  // Touching (within rounding of the coordinates) counts as separated.
  const double tol = 1e-9 * (1 + std::abs(a_lo) + std::abs(b_hi));
  return a_hi <= b_lo + tol || b_hi <= a_lo + tol;
}
}  // namespace

bool box_meets_convex(const Box& box, const Polygon& convex) {
  if (convex.size() < 3) return false;
  // Called for every candidate label position: no allocation here.
  const std::array<Vec2, 4> corners = {box.min, Vec2(box.max.x(), box.min.y()), box.max,
                                       Vec2(box.min.x(), box.max.y())};
  // Two convex sets have disjoint interiors iff some edge normal of one separates them;
  // the box's normals are the two coordinate axes.
  if (separates(corners, convex, Vec2(1, 0)) || separates(corners, convex, Vec2(0, 1)))
    return false;
  // On its own outward edge normal the polygon reaches no further than the edge itself,
  // so each edge is one O(1) test: the box wholly beyond the edge's line.
  for (std::size_t i = 0, n = convex.size(); i < n; ++i) {
    const Vec2 e = convex[(i + 1) % n] - convex[i];
    if (e.squaredNorm() == 0) continue;
    const Vec2 outward = Vec2(e.y(), -e.x()).normalized();
    double box_lo = outward.dot(corners[0]);
    for (const Vec2& c : corners) box_lo = std::min(box_lo, outward.dot(c));
    const double edge = outward.dot(convex[i]);
    if (box_lo >= edge - 1e-9 * (1 + std::abs(edge))) return false;
  }
  return true;
}

Vec2 nearest_point_on_box(const Box& b, const Vec2& p) {
  return {std::clamp(p.x(), b.min.x(), b.max.x()), std::clamp(p.y(), b.min.y(), b.max.y())};
}

Box bounding_box(const Polygon& polygon) {
  if (polygon.empty()) return {};
  Box b{polygon.front(), polygon.front()};
  for (const Vec2& p : polygon) {
    b.min = b.min.cwiseMin(p);
    b.max = b.max.cwiseMax(p);
  }
  return b;
}

}  // namespace covtrack::client
