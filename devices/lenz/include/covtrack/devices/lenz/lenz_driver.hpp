#pragma once
// The Lenz Digital Plus train tracker: occupancy feedback from an LI101F or LI-USB over
// a serial port, dead reckoning between section boundaries, one pose stream per vehicle.
//
// At (re)connection it asks for the interface version, the command-station version and
// status, and the state of every feedback module the layout uses; a status request every
// keepalive_s keeps the link alive. When the port goes away or falls silent the vehicles
// are reported LOST and the port is reopened until it comes back. Two cases return an
// error, so that the daemon marks the device FAILED and restarts it: a port that cannot
// be opened at the very start, and a line that delivers bytes but no answer to the
// status request for no_valid_frames_s ("no valid frames for N s": noise, a wrong baud
// rate, another device on the port).
#include <memory>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/devices/lenz/lenz_config.hpp"

namespace covtrack::lenz {

// Every time the driver works with (keepalives, timeouts, the sample schedule, dead
// reckoning, the stamps on its poses) comes from `clock`.
std::unique_ptr<Driver> make_lenz_driver(const LenzConfig& config, DriverClock& clock = real_clock());

}  // namespace covtrack::lenz
