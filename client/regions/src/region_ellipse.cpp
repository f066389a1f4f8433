#include <algorithm>
#include <cmath>
#include <numbers>

#include "covtrack/client/regions.hpp"

namespace covtrack::client {

int circumscribed_polygon_sides(double semi_major_px, double max_error_px, int min_sides,
                                int max_sides) {
  if (!(semi_major_px > 0) || !(max_error_px > 0)) return min_sides;
  // a (1/cos(pi/N) - 1) <= e  <=>  pi/N <= acos(1 / (1 + e/a)).
  const double half_angle = std::acos(1.0 / (1.0 + max_error_px / semi_major_px));
  const double n = std::ceil(std::numbers::pi / half_angle);
  return static_cast<int>(std::clamp(n, double(min_sides), double(max_sides)));
}

Polygon circumscribed_ellipse_polygon(const Vec2& center, const Mat2& C, double scale,
                                      int sides) {
  const EllipseAxes e = ellipse_axes(C);
  // Affine map of the unit circle onto the ellipse: rotation * diag(semi-axes).
  const double c = std::cos(e.angle_rad), s = std::sin(e.angle_rad);
  Mat2 A;
  A << c, -s, s, c;
  A = A * Eigen::Vector2d(e.major_px, e.minor_px).asDiagonal();
  A *= scale / std::cos(std::numbers::pi / sides);  // circumscribed, not inscribed
  Polygon out(sides);
  // Rotation by 2 pi / N as a recurrence: one sin/cos pair per polygon, not per vertex.
  const double step = 2 * std::numbers::pi / sides;
  const double cs = std::cos(step), sn = std::sin(step);
  Vec2 u(1, 0);
  for (int k = 0; k < sides; ++k) {
    out[k] = center + A * u;
    u = Vec2(cs * u.x() - sn * u.y(), sn * u.x() + cs * u.y());
  }
  return out;
}

}  // namespace covtrack::client
