#pragma once
// The keys that set a pose driver's plausibility gate (motion_gate.hpp): what the
// tracked thing can physically do. Defaults cover a hand or a head with a wide margin.
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/motion_gate.hpp"

namespace covtrack {

std::vector<KeySpec> motion_limit_keys();

MotionLimits read_motion_limits(TableReader& r);

}  // namespace covtrack
