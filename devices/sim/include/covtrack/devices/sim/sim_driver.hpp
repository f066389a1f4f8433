#pragma once
// The simulated tracker: N sensors on a moving rig, reporting poses whose noise is
// drawn from exactly the covariance they report, plus the noise-free truth.
#include <memory>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/sim/sim_config.hpp"

namespace covtrack::sim {

// `run_index` counts restarts, so that a restarted driver draws fresh noise.
std::unique_ptr<Driver> make_sim_driver(const SimConfig& config, std::uint64_t run_index);

}  // namespace covtrack::sim
