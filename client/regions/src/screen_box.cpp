#include "covtrack/client/screen_box.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace covtrack::client {

namespace {
using Corners = std::array<Vec2, 4>;

// The box's corners in box_polygon's order, without an allocation.
Corners corners_of(const Box& box) {
  return {box.min, Vec2(box.max.x(), box.min.y()), box.max, Vec2(box.min.x(), box.max.y())};
}
}  // namespace

Polygon box_polygon(const Box& b) {
  const Corners c = corners_of(b);
  return {c.begin(), c.end()};
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

// The polygon's extent [b_lo, b_hi] on `axis` separates the corners'.
bool separates(const Corners& corners, const Vec2& axis, double b_lo, double b_hi) {
  double a_lo, a_hi;
  project(corners, axis, a_lo, a_hi);
  // Touching (within rounding of the coordinates) counts as separated.
  const double tol = 1e-9 * (1 + std::abs(a_lo) + std::abs(b_hi));
  return a_hi <= b_lo + tol || b_hi <= a_lo + tol;
}

// On its own outward edge normal the polygon reaches no further than the edge itself,
// so each edge is one O(1) test: the box wholly beyond the edge's line. The box's lowest
// reach along the normal is its centre's less its half-extents' (the corner that points
// most against the normal): one product per edge instead of one per corner. The label
// placer makes this test for every candidate place against the objects near it.
struct CentredBox {
  Vec2 center, half;
  explicit CentredBox(const Box& b) : center(0.5 * (b.min + b.max)), half(0.5 * (b.max - b.min)) {}
};
bool beyond_edge(const CentredBox& box, const Vec2& outward, double edge) {
  const double box_lo = outward.dot(box.center) - std::abs(outward.x()) * box.half.x() - std::abs(outward.y()) * box.half.y();
  return box_lo >= edge - 1e-9 * (1 + std::abs(edge));
}

// Calls side(outward, offset) for each edge of non-zero length until one returns true.
template <class Side>
bool any_side(const Polygon& convex, Side&& side) {
  for (std::size_t i = 0, n = convex.size(); i < n; ++i) {
    const Vec2 e = convex[(i + 1) % n] - convex[i];
    if (e.squaredNorm() == 0) continue;
    const Vec2 outward = Vec2(e.y(), -e.x()).normalized();
    if (side(outward, outward.dot(convex[i]))) return true;
  }
  return false;
}
}  // namespace

bool box_meets_convex(const Box& box, const Polygon& convex) {
  if (convex.size() < 3) return false;
  // Called for every candidate label position: no allocation here.
  const Corners corners = corners_of(box);
  // Two convex sets have disjoint interiors iff some edge normal of one separates them;
  // the box's normals are the two coordinate axes.
  for (const Vec2& axis : {Vec2(1, 0), Vec2(0, 1)}) {
    double lo, hi;
    project(convex, axis, lo, hi);
    if (separates(corners, axis, lo, hi)) return false;
  }
  const CentredBox centred(box);
  return !any_side(convex, [&](const Vec2& outward, double edge) { return beyond_edge(centred, outward, edge); });
}

void convex_sides(const Polygon& convex, ConvexSides& sides) {
  sides.outward.clear();
  sides.offset.clear();
  sides.usable = convex.size() >= 3;
  if (!sides.usable) return;
  project(convex, Vec2(1, 0), sides.x_lo, sides.x_hi);
  project(convex, Vec2(0, 1), sides.y_lo, sides.y_hi);
  any_side(convex, [&](const Vec2& outward, double edge) {
    sides.outward.push_back(outward);
    sides.offset.push_back(edge);
    return false;
  });
}

bool box_meets_convex(const Box& box, const ConvexSides& sides) {
  if (!sides.usable) return false;
  const Corners corners = corners_of(box);
  if (separates(corners, Vec2(1, 0), sides.x_lo, sides.x_hi) || separates(corners, Vec2(0, 1), sides.y_lo, sides.y_hi))
    return false;
  const CentredBox centred(box);
  for (std::size_t i = 0; i < sides.outward.size(); ++i)
    if (beyond_edge(centred, sides.outward[i], sides.offset[i])) return false;
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
