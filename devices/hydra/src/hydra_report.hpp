#pragma once
// Razer Hydra (Sixense) HID reports, from the publicly documented format (VRPN's driver
// and community notes): in motion-controller mode the data interface (0) sends 52-byte
// input reports; controller i starts at byte 8 + 22 i with little-endian int16
// x y z (mm), int16 quaternion w x y z (/32768), a button byte, int16 joystick x y
// (/32768) and a trigger byte (/255). The magnetic field gives each position only up to
// its sign (two hemispheres); HemisphereTracker resolves it by continuity.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "covtrack/devices/hydra/hydra_driver.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::hydra {

inline constexpr int kDataInterface = 0;
inline constexpr std::size_t kReportSize = 52;
inline constexpr std::size_t kControllerOffset[2] = {8, 30};

struct ControllerState {
  Vec3 position_m = Vec3::Zero();  // as reported: sign not yet resolved
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  std::uint8_t buttons = 0;        // bumper 0x01, 3 0x02, 1 0x04, 2 0x08, 4 0x10, start 0x20, stick 0x40
  double joystick_x = 0, joystick_y = 0;  // -1..1
  double trigger = 0;                     // 0..1
};

struct HydraReport {
  std::array<ControllerState, 2> controllers;
};

// Parses one input report; an error says what is wrong (size, non-unit quaternion).
Result<HydraReport> parse_hydra_report(std::span<const std::uint8_t> bytes);

// The inverse, for tests (the format as documented, not captured bytes).
std::array<std::uint8_t, kReportSize> build_hydra_report(const HydraReport& report);

// Feature report 0 (report id byte first, 91 bytes) that switches the base into
// motion-controller mode, and the one that switches it back to gamepad mode.
std::array<std::uint8_t, 91> motion_mode_feature_report();
std::array<std::uint8_t, 91> gamepad_mode_feature_report();

// Picks the sign of each position: the one nearer the previous position; at the start
// the left controller (0) is assumed left of the base (x < 0), the right one right.
class HemisphereTracker {
 public:
  Vec3 resolve(int controller, const Vec3& reported);

 private:
  std::array<std::optional<Vec3>, 2> last_;
};

}  // namespace covtrack::hydra
