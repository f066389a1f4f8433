#pragma once
// The simulated tracker: N sensors on a moving rig, reporting poses whose noise is
// drawn from exactly the covariance they report, plus the noise-free truth.
#include <memory>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/devices/sim/sim_config.hpp"

namespace covtrack::sim {

// `run_index` counts restarts, so that a restarted driver draws fresh noise. Its samples
// are timed by `clock` (tests run it on simulated time).
std::unique_ptr<Driver> make_sim_driver(const SimConfig& config, std::uint64_t run_index,
                                        DriverClock& clock = real_clock());

}  // namespace covtrack::sim
