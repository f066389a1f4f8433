#pragma once
// The Lenz Digital Plus train tracker: occupancy feedback from an LI101F or LI-USB over
// a serial port, dead reckoning between section boundaries, one pose stream per vehicle.
//
// At (re)connection it asks for the interface version, the command-station version and
// status, and the state of every feedback module the layout uses; a status request every
// keepalive_s keeps the link alive. When the port goes away or falls silent the vehicles
// are reported LOST and the port is reopened until it comes back. Only a port that
// cannot be opened at the very start is returned as an error (the daemon then retries).
#include <memory>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/lenz/lenz_config.hpp"

namespace covtrack::lenz {

std::unique_ptr<Driver> make_lenz_driver(const LenzConfig& config);

}  // namespace covtrack::lenz
