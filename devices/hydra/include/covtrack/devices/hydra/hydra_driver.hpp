#pragma once
// The Razer Hydra driver (type = "hydra") over hidapi: switches the base into
// motion-controller mode with its feature report, reads both controllers' poses, and
// reports them with the configured covariance (default: the manufacturer's 1 mm / 1 degree).
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/devices/motion_gate.hpp"

namespace covtrack::hydra {

// The base's USB ids: the driver opens the device by them, `covtrack devices` names it.
inline constexpr std::uint16_t kVendorId = 0x1532;
inline constexpr std::uint16_t kProductId = 0x0300;

struct HydraConfig {
  std::string device;
  std::string parent_frame = "world";
  std::string hid_path;  // empty: the first Hydra found
  std::array<std::string, 2> sensors = {"left", "right"};
  Mat6 covariance = Mat6::Zero();
  double rate_hz = 250;
  double watchdog_periods = 4;
  // No report that parses for this long, whatever the base sends: FAILED, restarted.
  double no_valid_frames_s = 10;
  MotionLimits motion;  // the plausibility gate (src/hydra_stream.hpp)
};

// The default covariance: Sixense/Razer state 1 mm position and 1 degree orientation.
Mat6 hydra_default_covariance();

const TableSpec& hydra_device_spec();
HydraConfig read_hydra_config(TableReader& device, const std::string& device_name);

// Every timeout, mode-switch retry and time stamp of the driver is on `clock`.
std::unique_ptr<Driver> make_hydra_driver(const HydraConfig& config, DriverClock& clock = real_clock());

}  // namespace covtrack::hydra
