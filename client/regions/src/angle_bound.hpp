#pragma once
// The angle bound of the whole-object scale (region_scale.cpp) and of the outer region's
// arc split (region_outer.cpp), here so that its test can reach it.
#include <algorithm>
#include <cmath>
#include <numbers>

namespace covtrack::client {

// An upper bound, within 2e-5 rad, of the angle atan2(y, x) in [0, pi] for y >= 0, with
// one division and no square root (each is a long wait in a block's chain): the octant's
// angle atan(s), s = min(y, |x|) / max(y, |x|) in [0, 1], by a polynomial within 1.7e-6
// rad of it, then folded out to the quadrant (pi/2 - that where y > |x|) and to the half
// plane (pi - that where x < 0). Unit vectors are not needed: the angle between (x, y)
// and the axis does not change when both are scaled alike.
inline double angle_at_most(double y, double x) {
  constexpr double kMargin = 1e-5;  // over the polynomial's error (AngleBound tests both)
  const double ax = std::abs(x), low = std::min(y, ax), high = std::max(y, ax);
  const double s = low / std::max(high, 1e-300), s2 = s * s;  // 0 where both are 0
  const double octant =
      s * (0.99997726 + s2 * (-0.33262347 + s2 * (0.19354346 + s2 * (-0.11643287 + s2 * (0.05265332 + s2 * -0.01172120)))));
  const double quadrant = y > ax ? std::numbers::pi / 2 - octant : octant;
  const double half_plane = x < 0 ? std::numbers::pi - quadrant : quadrant;
  return std::min(half_plane + kMargin, std::numbers::pi);
}

}  // namespace covtrack::client
