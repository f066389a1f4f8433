#include "driver_table.hpp"

#include "covtrack/devices/fiducial/fiducial_driver.hpp"
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
      {"fiducial", "AprilTag fiducial tracker: tag poses from a camera, video or image sequence, "
       "covariance from a calibrated corner noise model",
       {&fiducial::fiducial_device_spec(), &fiducial::fiducial_tag_spec()},
       [](TableReader& device, const std::string& name) -> DriverFactory {
         fiducial::FiducialConfig config = fiducial::read_fiducial_config(device, name);
         return [config](std::uint64_t run) { return fiducial::make_fiducial_driver(config, run); };
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
