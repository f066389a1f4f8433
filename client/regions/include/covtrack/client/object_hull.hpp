#pragma once
// The vertices of an object's 3-D convex hull (dissertation 5.4, docs/background.md):
// computed once per object, so the per-frame projection handles only the points that can
// bound its screen region. Every point of the 2-D hull of a projection is the image of a
// 3-D hull vertex, so nothing is lost by dropping the others. That holds exactly for a
// pinhole (it maps segments to segments); lens distortion bends them, so with strong
// distortion a dropped point near the hull's silhouette can sit outside the screen hull by
// a fraction of a pixel.
#include <array>
#include <span>
#include <vector>

#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::client {

// Indices (ascending) of the points that are vertices of their convex hull. Flat sets are
// handled in their plane (a panel, a quad), collinear ones by their two ends, one point by
// itself. Fails on an empty set or a non-finite coordinate.
Result<std::vector<int>> convex_hull_indices_3d(std::span<const Vec3> points);

// The hull's surface as triangles of point indices, counter-clockwise seen from outside,
// for drawing an object that has no model of its own. A flat set gives a fan over its
// outline (drawn from either side), a line or a point none. Fails as above.
using Triangle = std::array<int, 3>;
Result<std::vector<Triangle>> convex_hull_triangles_3d(std::span<const Vec3> points);

}  // namespace covtrack::client
