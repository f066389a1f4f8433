#include "driver_table.hpp"

#include "covtrack/devices/lenz/layout_config.hpp"
#include "covtrack/devices/lenz/lenz_driver.hpp"
#include "covtrack/devices/sim/sim_driver.hpp"

namespace covtrack::server {

const std::vector<DriverType>& driver_types() {
  static const std::vector<DriverType> table = {
      {"sim", "simulated tracker: sensors on a moving rig, noise drawn from the reported covariance",
       {&sim::sim_device_spec(), &sim::sim_motion_spec()},
       [](TableReader& device, const std::string& name) -> DriverFactory {
         sim::SimConfig config = sim::read_sim_config(device, name);
         return [config](std::uint64_t run) { return sim::make_sim_driver(config, run); };
       }},
      {"lenz", "Lenz Digital Plus train tracker (LI101F / LI-USB): section occupancy and dead reckoning, seed 7.3",
       [] {
         std::vector<const TableSpec*> specs{&lenz::lenz_device_spec()};
         for (const auto* s : lenz::layout_specs()) specs.push_back(s);
         return specs;
       }(),
       [](TableReader& device, const std::string& name) -> DriverFactory {
         lenz::LenzConfig config = lenz::read_lenz_config(device, name);
         return [config](std::uint64_t) { return lenz::make_lenz_driver(config); };
       }},
  };
  return table;
}

const DriverType* find_driver_type(std::string_view type) {
  for (const auto& t : driver_types())
    if (t.type == type) return &t;
  return nullptr;
}

}  // namespace covtrack::server
