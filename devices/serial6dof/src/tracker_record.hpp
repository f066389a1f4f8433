#pragma once
// What the serial 6-DOF decoders produce: one station's pose as the device sent it,
// converted to SI units, plus the device's own trouble flag. Pure data, no clock.
#include <cstdint>
#include <optional>
#include <string>
#include <variant>

#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::serial6dof {

struct TrackerRecord {
  int station = 0;                 // as the device numbers it (1-based)
  Vec3 position_m = Vec3::Zero();  // receiver origin in the source frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // source <- receiver
  bool trouble = false;            // the device flagged this record (weak signal, error code)
  int status_code = 0;             // the raw status byte/letter, for messages
  std::optional<double> device_time_s;       // timestamp item, when in the output list
  std::optional<std::uint32_t> buttons;      // buttons / stylus item, when in the list
};

// A reply that is not a pose record: a status record, a who-am-I text, a setting.
struct DeviceReply {
  char command = 0;          // the command it answers ('S', 'U', 0x16 ...)
  int station = 0;
  int error_code = 0;        // 0 = none
  std::string payload;       // raw bytes after the header
};

using DecodedItem = std::variant<TrackerRecord, DeviceReply>;

inline double metres_per_unit(Units u) { return u == Units::Inches ? 0.0254 : 0.01; }

}  // namespace covtrack::serial6dof
