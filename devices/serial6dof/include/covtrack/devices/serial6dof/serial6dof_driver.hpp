#pragma once
// The serial 6-DOF driver (FASTRAK / IS-900, LIBERTY / PATRIOT, Flock of Birds): opens
// the port, resets and configures the unit, then streams poses with the covariance of
// src/covariance_model.hpp. A station silent for watchdog_periods is reported LOST; a unit
// that stays silent, or a port that goes away, fails the driver so that the daemon
// restarts it, and every restart resets the unit. All waiting happens on this driver's
// own thread: a reset never delays another device.
//
// Its options (types "fastrak", "liberty", "flock"), read from the [devices.<name>] table
// and its [[devices.<name>.stations]] tables, and the USB ids of the units that have a
// USB port.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/devices/motion_gate.hpp"

namespace covtrack::serial6dof {

enum class Protocol { Fastrak, Liberty, Flock };
enum class Model { Fastrak, Is900, Liberty, Patriot, Flock };
enum class Units { Inches, Centimetres };

// Output-list items after position (2) and quaternion (11), in list order
// (FASTRAK manual; IS-900 user guide). The driver always asks for 2, 11, then these,
// then 1 (CR LF).
enum class FastrakExtra { Timestamp = 21, Buttons = 22, Stylus = 16, Joystick = 23 };

// Output-list items after position (2) and quaternion (7) (PDI SDK).
enum class LibertyExtra { Timestamp = 8, FrameCount = 9, Stylus = 10 };

// A LIBERTY's own USB port (the RS-232 port needs nothing): it enumerates without its
// firmware first, then again with it loaded.
inline constexpr std::uint16_t kPolhemusVendorId = 0x0f44;
inline constexpr std::uint16_t kLibertyProductId = 0xff20;
inline constexpr std::uint16_t kLibertyNoFirmwareProductId = 0xff21;

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

// Every wait, timeout and time stamp of the driver is on `clock`.
std::unique_ptr<Driver> make_serial6dof_driver(const Serial6dofConfig& config, std::uint64_t run_index,
                                               DriverClock& clock = real_clock());

}  // namespace covtrack::serial6dof
