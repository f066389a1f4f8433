#pragma once
// The vrpn driver (type = "vrpn"): connects to a tracker that a vrpn_server serves
// ("Tracker0@host:port") over TCP, speaking VRPN's protocol itself, and republishes its
// sensors with the covariance the config gives (VRPN carries none). A dropped or
// silent connection reports every sensor LOST and fails the driver, whose restarts
// (with the daemon's growing back-off) reconnect.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/vrpn/tracker_address.hpp"

namespace covtrack::vrpn {

struct VrpnSensorConfig {
  int number = 0;    // VRPN's sensor number
  std::string name;  // covtrack's sensor name (child frame)
  Mat6 covariance = Mat6::Zero();
};

struct VrpnConfig {
  std::string device;
  std::string parent_frame = "world";
  TrackerAddress tracker;
  // Listed sensors only; when none is listed, every sensor as "sensor<N>" with this.
  std::vector<VrpnSensorConfig> sensors;
  std::optional<Mat6> covariance;
  double connect_timeout_s = 2;
  // Nothing from the device (no report, no answer to the pings sent each second) for
  // this long: the connection is dead although open.
  double silence_timeout_s = 3;
  // A sensor with no report for this long is LOST (0: never).
  double sensor_timeout_s = 1;
};

const TableSpec& vrpn_device_spec();
const TableSpec& vrpn_sensor_spec();
VrpnConfig read_vrpn_config(TableReader& device, const std::string& device_name);

// Every timeout, ping and time stamp of the driver is on `clock`; connecting and sending
// keep their own limits in real time (they wait on the operating system).
std::unique_ptr<Driver> make_vrpn_driver(const VrpnConfig& config, DriverClock& clock = real_clock());

}  // namespace covtrack::vrpn
