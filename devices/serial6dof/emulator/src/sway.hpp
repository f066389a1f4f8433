#pragma once
// A receiver's motion about its resting pose: smooth, bounded, never periodic in all
// axes at once, so a gate or filter cannot lock onto one frequency.
#include <cstddef>

#include "covtrack/protocol/se3.hpp"

namespace covtrack::emulate6dof {

// The displacement T_rest_now at `t_s` for the station at `index`: every tangent axis a
// sine of amplitude amplitude_m (translation) or amplitude_rad (rotation), at its own
// frequency between base_hz and 1.7 x base_hz and its own phase.
Pose sway(double t_s, std::size_t index, double amplitude_m, double amplitude_rad, double base_hz);

}  // namespace covtrack::emulate6dof
