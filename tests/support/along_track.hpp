#pragma once
// Where on a Lenz layout's loop a true position lies: the along-track coordinate s of the
// nearest point, on a 2 mm grid and then a 0.02 mm grid around it (truth lies on the
// track, so the distance found is ~0).
#include <cmath>

#include "covtrack/protocol/se3.hpp"
#include "track_layout.hpp"

namespace covtrack::test {

inline double along_track_of(const lenz::TrackLayout& layout, const Vec3& position) {
  const auto nearest = [&](double from, double to, double step) {
    double best = from, best_d = INFINITY;
    for (double s = from; s <= to; s += step)
      if (const double d = (layout.pose_at(layout.wrap(s)).translation() - position).squaredNorm(); d < best_d)
        best = s, best_d = d;
    return best;
  };
  const double coarse = nearest(0, layout.length_m(), 2e-3);
  return layout.wrap(nearest(coarse - 2e-3, coarse + 2e-3, 2e-5));
}

}  // namespace covtrack::test
