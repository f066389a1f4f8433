#pragma once
// Shared by the widget tests: rectangles and random convex polygons.
#include <random>

#include "covtrack/client/regions.hpp"

namespace covtrack::client::widget_testing {

// The axis-aligned rectangle from (x0, y0) to (x1, y1).
inline Polygon square(double x0, double y0, double x1, double y1) {
  return {Vec2(x0, y0), Vec2(x1, y0), Vec2(x1, y1), Vec2(x0, y1)};
}

// Hull of 3..max_points random points in a box of `half_size` around `center`; on the
// integer grid when `grid` (many collinear and shared coordinates: degenerate cases).
inline Polygon random_convex(std::mt19937_64& rng, const Vec2& center, double half_size,
                             int max_points = 20, bool grid = false) {
  std::uniform_int_distribution<int> count(3, max_points);
  std::uniform_real_distribution<double> u(-half_size, half_size);
  for (;;) {
    std::vector<Vec2> pts;
    for (int i = 0, n = count(rng); i < n; ++i) {
      Vec2 p(u(rng), u(rng));
      if (grid) p = p.array().round().matrix();
      pts.push_back(center + p);
    }
    Polygon hull = convex_hull(pts);
    if (hull.size() >= 3 && polygon_area(hull) > 1e-6) return hull;
  }
}

}  // namespace covtrack::client::widget_testing
