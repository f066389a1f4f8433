#pragma once
// Cross products in the image plane, shared by the region and polygon sources.
#include "covtrack/protocol/camera.hpp"  // Vec2

namespace covtrack::client {

// a x b: positive when b points to the left of a (counter-clockwise).
inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// (a - o) x (b - o): positive when o, a, b turn counter-clockwise.
inline double cross(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

}  // namespace covtrack::client
