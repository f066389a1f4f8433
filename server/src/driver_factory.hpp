#pragma once
// The run-time half of the driver table: a fresh driver from a device's options, for
// each (re)start. Kept apart from driver_table.hpp so that reading and checking a config
// does not link any driver's run-time code (nor the fiducial tracker's vision library).
#include <cstdint>
#include <memory>

#include "covtrack/devices/driver.hpp"
#include "driver_table.hpp"

namespace covtrack::server {

// `run_index` counts restarts (the simulated tracker draws fresh noise on each).
std::unique_ptr<Driver> make_driver(const DriverOptions& options, std::uint64_t run_index);

}  // namespace covtrack::server
