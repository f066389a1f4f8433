#pragma once
// Polygons in pixels: counter-clockwise in (u, v) arithmetic (positive signed area), no
// repeated closing vertex. The type and the operations the regions build on (hulls,
// clipping, containment); convex_polygon.hpp has those the widgets add.
#include <cstddef>
#include <span>
#include <vector>

#include "covtrack/client/camera.hpp"  // Vec2

namespace covtrack::client {

using Polygon = std::vector<Vec2>;

// ---- Polygons (region_polygon.cpp) ----
// Counter-clockwise from the lowest x (of those, the lowest y); collinear points dropped.
// Andrew's monotone chain, or for up to 8 points on a CPU with AVX2 each point's successor
// found side by side (the same hull, without a sort). Indices into `points`.
std::vector<int> convex_hull_indices(std::span<const Vec2> points);
// The same into `hull` (no allocation once its capacity suffices).
void convex_hull_indices(std::span<const Vec2> points, std::vector<int>& hull);
Polygon convex_hull(std::span<const Vec2> points);
// The part of a convex polygon with normal . x <= offset.
Polygon clip_half_plane(const Polygon& convex, const Vec2& normal, double offset);
// The same into `out`, which has room for convex.size() + 1 points (2 * size() for a
// polygon that may not be convex); returns the count.
std::size_t clip_half_plane(std::span<const Vec2> convex, const Vec2& normal, double offset,
                            Vec2* out);
// Inside or within tolerance_px of a convex polygon.
bool polygon_contains(const Polygon& convex, const Vec2& point, double tolerance_px = 1e-9);
double polygon_area(const Polygon& polygon);

}  // namespace covtrack::client
