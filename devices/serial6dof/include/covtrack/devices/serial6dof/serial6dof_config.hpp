#pragma once
// Options of the serial 6-DOF drivers (types "fastrak", "liberty", "flock"), read from
// their [devices.<name>] table and its [[devices.<name>.stations]] tables.
#include <optional>
#include <string>
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/motion_gate.hpp"
#include "covtrack/devices/serial6dof/device_model.hpp"
#include "covtrack/devices/serial6dof/fastrak_decoder.hpp"
#include "covtrack/devices/serial6dof/liberty_decoder.hpp"

namespace covtrack::serial6dof {

struct StationConfig {
  int number = 1;                  // as the device numbers it (Flock: the FBB address)
  std::string name;                // sensor name (child frame)
  std::optional<Mat6> covariance;  // BODY; none: the model's static accuracy
};

struct Serial6dofConfig {
  std::string device;
  std::string parent_frame = "world";
  Model model = Model::Fastrak;
  std::string port;
  int baud = 115200;
  std::vector<StationConfig> stations;
  Units units = Units::Centimetres;             // Fastrak and Liberty
  std::vector<FastrakExtra> fastrak_extras;
  std::vector<LibertyExtra> liberty_extras;
  double flock_position_scale_in = 36;          // Flock
  double rate_hz = 0;                           // per station
  double watchdog_periods = 1.5;  // + the read poll (a quarter of it): LOST within 2 periods
  bool reset_on_start = true;
  double reset_time_s = 10;
  double reply_timeout_s = 1.0;
  double trouble_inflation = 10;                // variance factor when the unit flags trouble
  double latency_s = 0;
  bool publish_raw = false;
  MotionLimits motion;                          // the plausibility gate

  double period_s() const { return 1.0 / rate_hz; }
  double watchdog_s() const { return watchdog_periods * period_s(); }
};

const TableSpec& serial6dof_device_spec(Protocol protocol);
const TableSpec& serial6dof_station_spec(Protocol protocol);

Serial6dofConfig read_serial6dof_config(TableReader& device, const std::string& device_name,
                                        Protocol protocol);

}  // namespace covtrack::serial6dof
