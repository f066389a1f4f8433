#include <set>
#include <string>

#include <fmt/format.h>

#include "covtrack/devices/covariance_keys.hpp"
#include "covtrack/devices/device_keys.hpp"
#include "covtrack/devices/vrpn/vrpn_driver.hpp"
#include "covtrack/protocol/channels.hpp"

namespace covtrack::vrpn {
namespace {
bool has_covariance(TableReader& r) { return r.has("covariance") || r.has("sigma_m") || r.has("sigma_rad"); }
}  // namespace

const TableSpec& vrpn_device_spec() {
  static const TableSpec spec = [] {
    TableSpec s{"devices.<name> (type = \"vrpn\")", "vrpn driver", device_common_keys()};
    const std::vector<KeySpec> own = {
        {"tracker", ValueType::String, "", "",
         "the VRPN tracker to read, as VRPN names it: \"Tracker0@host\" or \"Tracker0@host:port\" (port 3883 "
         "by default)"},
        {"sensors", ValueType::TableArray, "", "every sensor, as sensor<N>",
         "the VRPN sensors to publish: see devices.<name>.sensors (type = \"vrpn\"); others are dropped"},
        {"connect_timeout_s", ValueType::Float, "s", "2",
         "longest wait for the server to accept the connection and to send its VRPN cookie", 0.05, 60},
        {"silence_timeout_s", ValueType::Float, "s", "3",
         "nothing from the tracker (no report, no answer to the pings sent each second) for this long: "
         "every sensor LOST, the connection closed and made again after the daemon's restart back-off",
         0.5, 600},
        {"sensor_timeout_s", ValueType::Float, "s", "1",
         "a sensor without a report for this long is reported LOST (0: never, for a server that only "
         "sends changes)", 0, 600},
    };
    s.keys.insert(s.keys.end(), own.begin(), own.end());
    for (auto k : covariance_keys()) {
      k.default_value = "required unless every listed sensor gives its own";
      s.keys.push_back(k);
    }
    return s;
  }();
  return spec;
}

const TableSpec& vrpn_sensor_spec() {
  static const TableSpec spec = [] {
    TableSpec s{"devices.<name>.sensors (type = \"vrpn\")", "vrpn driver",
                {{"number", ValueType::Integer, "", "", "VRPN's sensor number", 0, 65535},
                 {"name", ValueType::String, "", "\"sensor<number>\"", "covtrack's sensor name (child frame)"}}};
    for (auto k : covariance_keys()) {
      k.default_value = "the device's";
      s.keys.push_back(k);
    }
    return s;
  }();
  return spec;
}

VrpnConfig read_vrpn_config(TableReader& r, const std::string& device_name) {
  VrpnConfig c;
  c.device = device_name;
  c.parent_frame = r.string("parent_frame", c.parent_frame);
  const std::string tracker = r.string("tracker");  // a missing one is reported here
  if (r.has("tracker")) {
    auto address = parse_tracker_address(tracker);
    if (address) c.tracker = *address;
    else r.error("tracker", address.error().message);
  }
  if (has_covariance(r)) c.covariance = read_covariance(r);
  std::set<int> numbers;  // one error per repeated sensor, not one per pair
  std::set<std::string> names;
  for (const toml::table* t : r.tables("sensors")) {
    TableReader s(*t, r.path("sensors") + fmt::format("[{}]", c.sensors.size()), vrpn_sensor_spec(), r.file(),
                  r.errors());
    VrpnSensorConfig sensor;
    sensor.number = static_cast<int>(s.integer("number", 0));
    sensor.name = s.string("name", fmt::format("sensor{}", sensor.number));
    if (!is_valid_name(sensor.name))
      s.error("name", fmt::format("'{}' is not a valid sensor name (1-{} of A-Z a-z 0-9 _ -)", sensor.name,
                                  covtrack::kMaxNameLength));
    if (has_covariance(s)) sensor.covariance = read_covariance(s);
    else if (c.covariance) sensor.covariance = *c.covariance;
    else s.error("number", "no covariance: give sigma_m and sigma_rad (or covariance) here or for the device");
    if (!numbers.insert(sensor.number).second)
      s.error("number", fmt::format("sensor {} is listed twice", sensor.number));
    if (!names.insert(sensor.name).second) s.error("name", fmt::format("sensor name '{}' is used twice", sensor.name));
    c.sensors.push_back(sensor);
  }
  if (c.sensors.empty() && !c.covariance)
    r.error("sigma_m", "no covariance: VRPN carries none, so give sigma_m and sigma_rad (or covariance)");
  c.connect_timeout_s = r.number("connect_timeout_s", c.connect_timeout_s);
  c.silence_timeout_s = r.number("silence_timeout_s", c.silence_timeout_s);
  c.sensor_timeout_s = r.number("sensor_timeout_s", c.sensor_timeout_s);
  return c;
}

}  // namespace covtrack::vrpn
