#pragma once
// Axis-aligned boxes in pixels (labels, selection targets, the screen) and their tests
// against each other and against convex polygons.
#include <vector>

#include "covtrack/client/polygon.hpp"

namespace covtrack::client {

struct Box {
  Vec2 min = Vec2::Zero();  // top-left corner (u, v), px
  Vec2 max = Vec2::Zero();  // bottom-right corner

  double width() const { return max.x() - min.x(); }
  double height() const { return max.y() - min.y(); }
  Vec2 center() const { return 0.5 * (min + max); }
};

// Inline: the label placer's policies make dozens per label.
inline Box box_at_center(const Vec2& center_px, const Vec2& size_px) {
  return {center_px - 0.5 * size_px, center_px + 0.5 * size_px};
}
inline Box box_at_corner(const Vec2& min_px, const Vec2& size_px) { return {min_px, min_px + size_px}; }

// Interiors meet (boxes that only touch along an edge do not overlap). Inline: the label
// placer and the space manager test many pairs.
inline bool boxes_overlap(const Box& a, const Box& b) {
  return a.min.x() < b.max.x() && b.min.x() < a.max.x() && a.min.y() < b.max.y() && b.min.y() < a.max.y();
}
// `inner` lies within `outer` (within tolerance_px). Inline: the label placer asks it of
// every candidate place.
inline bool box_inside(const Box& inner, const Box& outer, double tolerance_px = 1e-9) {
  return inner.min.x() >= outer.min.x() - tolerance_px && inner.min.y() >= outer.min.y() - tolerance_px &&
         inner.max.x() <= outer.max.x() + tolerance_px && inner.max.y() <= outer.max.y() + tolerance_px;
}
// The box as a counter-clockwise polygon.
Polygon box_polygon(const Box& box);
// The interiors of the box and of a convex polygon meet (separating-axis test).
bool box_meets_convex(const Box& box, const Polygon& convex);

// A convex polygon readied for many box_meets_convex tests: its extents along the two
// axes and its edges' outward unit normals, each computed once instead of once per box
// (the label placer tests every candidate place against the objects near it). The same
// answers as box_meets_convex, bit for bit.
struct ConvexSides {
  double x_lo = 0, x_hi = 0, y_lo = 0, y_hi = 0;
  std::vector<Vec2> outward;  // of each edge of non-zero length
  std::vector<double> offset;  // outward . the edge's first vertex
  bool usable = false;         // three vertices or more
};
void convex_sides(const Polygon& convex, ConvexSides& sides);  // keeps sides' memory
bool box_meets_convex(const Box& box, const ConvexSides& sides);
// The point of the box nearest to `point` (the point itself when inside).
Vec2 nearest_point_on_box(const Box& box, const Vec2& point);
// Smallest box holding the polygon (a zero box for an empty one).
Box bounding_box(const Polygon& polygon);

}  // namespace covtrack::client
