#pragma once
// Convex polygon operations the widgets need beyond polygon.hpp: intersection in linear
// time, centroid. Polygons as in polygon.hpp: counter-clockwise (positive signed area), no
// repeated closing vertex. (The slow reference the intersection is tested against is in
// tests/support.)
#include "covtrack/client/polygon.hpp"

namespace covtrack::client {

// Intersection of two convex polygons in O(n + m) (slab method, Shamos): each polygon is
// split at its leftmost and rightmost vertices into a lower and an upper x-monotone chain;
// one merge of the chains' x coordinates gives slabs in which all four chains are straight,
// and there the intersection is max(lower chains) <= y <= min(upper chains). Empty when
// the interiors do not meet or an input has fewer than 3 vertices.
Polygon intersect_convex(const Polygon& a, const Polygon& b);

// Area centroid; the vertex mean when the area is zero; (0, 0) when empty.
Vec2 polygon_centroid(const Polygon& polygon);

// Largest distance from `center` to a vertex.
double polygon_radius(const Polygon& polygon, const Vec2& center);

// At least 3 vertices, all finite.
bool is_usable_polygon(const Polygon& polygon);

}  // namespace covtrack::client
