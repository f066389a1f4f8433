#pragma once
// The serial 6-DOF driver (FASTRAK / IS-900, LIBERTY / PATRIOT, Flock of Birds): opens
// the port, resets and configures the unit, then streams poses with the covariance of
// covariance_model.hpp. A station silent for watchdog_periods is reported LOST; a unit
// that stays silent, or a port that goes away, fails the driver so that the daemon
// restarts it, and every restart resets the unit. All waiting happens on this driver's
// own thread: a reset never delays another device.
#include <memory>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/devices/serial6dof/serial6dof_config.hpp"

namespace covtrack::serial6dof {

// Every wait, timeout and time stamp of the driver is on `clock`.
std::unique_ptr<Driver> make_serial6dof_driver(const Serial6dofConfig& config, std::uint64_t run_index,
                                               DriverClock& clock = real_clock());

}  // namespace covtrack::serial6dof
