#pragma once
// The central, explicit table of driver types the daemon can host: their config tables
// and readers. Adding a driver means adding one row here and one case to make_driver
// (driver_factory.hpp); drivers never know about each other. This table reads and checks
// configs only: it links each driver's config reader, not its run-time code.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/fiducial/fiducial_driver.hpp"
#include "covtrack/devices/hydra/hydra_driver.hpp"
#include "covtrack/devices/lenz/lenz_driver.hpp"
#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"
#include "covtrack/devices/sim/sim_driver.hpp"
#include "covtrack/devices/vrpn/vrpn_driver.hpp"

namespace covtrack::server {

// A driver that a program hosting the daemon's Host makes itself (no config reads one);
// the argument counts restarts.
using DriverFactory = std::function<std::unique_ptr<Driver>(std::uint64_t run_index)>;

// One device's options as its driver's reader returned them. The fiducial options hold
// the vision code's types, so they stay behind the pointer their reader gives.
using DriverOptions = std::variant<sim::SimConfig, lenz::LenzConfig, serial6dof::Serial6dofConfig,
                                   hydra::HydraConfig, std::shared_ptr<const fiducial::FiducialConfig>,
                                   vrpn::VrpnConfig, DriverFactory>;

struct DriverType {
  std::string_view type;     // the `type` key of a [devices.<name>] table
  std::string_view summary;  // one line for --help and the schema document
  std::vector<const TableSpec*> specs;  // the device table's spec first, then sub-tables
  // Reads the device table (already checked against specs.front()); problems go to it.
  std::function<DriverOptions(TableReader& device, const std::string& name)> read;
};

const std::vector<DriverType>& driver_types();
const DriverType* find_driver_type(std::string_view type);

}  // namespace covtrack::server
