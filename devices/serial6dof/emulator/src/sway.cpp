#include "sway.hpp"

#include <cmath>
#include <numbers>

namespace covtrack::emulate6dof {

Pose sway(double t_s, std::size_t index, double amplitude_m, double amplitude_rad, double base_hz) {
  if (amplitude_m == 0 && amplitude_rad == 0) return Pose::Identity();
  constexpr double kFrequencyFactors[6] = {1.0, 1.31, 1.7, 1.13, 1.47, 1.59};
  Vec6 xi;
  for (int axis = 0; axis < 6; ++axis) {
    const double phase = 0.9 * axis + 2.1 * static_cast<double>(index);
    const double w = 2 * std::numbers::pi * base_hz * kFrequencyFactors[axis];
    xi[axis] = (axis < 3 ? amplitude_m : amplitude_rad) * std::sin(w * t_s + phase);
  }
  return se3_exp(xi);
}

}  // namespace covtrack::emulate6dof
