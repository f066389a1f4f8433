#include "driver_table.hpp"

namespace covtrack::server {
namespace {
// The three serial 6-DOF protocols share one driver; each has its own row and keys.
DriverType serial6dof_row(std::string_view type, std::string_view summary, serial6dof::Protocol p) {
  return {type, summary, {&serial6dof::serial6dof_device_spec(p), &serial6dof::serial6dof_station_spec(p)},
          [p](TableReader& device, const std::string& name) -> DriverOptions {
            return serial6dof::read_serial6dof_config(device, name, p);
          }};
}
}  // namespace

const std::vector<DriverType>& driver_types() {
  static const std::vector<DriverType> table = {
      {"sim", "simulated tracker: sensors on a moving rig, noise drawn from the reported covariance",
       {&sim::sim_device_spec(), &sim::sim_motion_spec()},
       [](TableReader& device, const std::string& name) -> DriverOptions {
         return sim::read_sim_config(device, name);
       }},
      {"lenz", "Lenz Digital Plus train tracker (LI101F / LI-USB): section occupancy and dead reckoning",
       [] {
         std::vector<const TableSpec*> specs{&lenz::lenz_device_spec()};
         for (const auto* s : lenz::layout_specs()) specs.push_back(s);
         return specs;
       }(),
       [](TableReader& device, const std::string& name) -> DriverOptions {
         return lenz::read_lenz_config(device, name);
       }},
      serial6dof_row("fastrak", "Polhemus FASTRAK or InterSense IS-900 (Fastrak mode) over a serial port",
                     serial6dof::Protocol::Fastrak),
      serial6dof_row("liberty", "Polhemus LIBERTY or PATRIOT over a serial port", serial6dof::Protocol::Liberty),
      serial6dof_row("flock", "Ascension Flock of Birds (POSITION/QUATERNION) over a serial port",
                     serial6dof::Protocol::Flock),
      {"hydra", "Razer Hydra: two controllers over HID (hidapi)", {&hydra::hydra_device_spec()},
       [](TableReader& device, const std::string& name) -> DriverOptions {
         return hydra::read_hydra_config(device, name);
       }},
      {"fiducial", "AprilTag fiducial tracker: tag poses from a camera, video or image sequence, "
       "covariance from a calibrated corner noise model",
       {&fiducial::fiducial_device_spec(), &fiducial::fiducial_tag_spec(), &fiducial::fiducial_bundle_spec(),
        &fiducial::fiducial_bundle_tag_spec(), &fiducial::corner_calibration_spec()},
       [](TableReader& device, const std::string& name) -> DriverOptions {
         return fiducial::read_fiducial_config(device, name);
       }},
      {"vrpn", "a tracker served by a vrpn_server (\"Tracker0@host\"), read over TCP, republished with a "
       "covariance from config",
       {&vrpn::vrpn_device_spec(), &vrpn::vrpn_sensor_spec()},
       [](TableReader& device, const std::string& name) -> DriverOptions {
         return vrpn::read_vrpn_config(device, name);
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
