#pragma once
// A device whose line yields nothing decodable for a configured time has failed,
// whatever bytes arrive. Line noise, a wrong baud rate or another device on the port
// keep a line busy without one frame the driver can use; taking any byte as a sign of
// life would keep such a device RUNNING forever with every sensor LOST. A driver tells
// this watchdog about each valid frame and, once it expires, returns its message as the
// run's failure: the daemon then reports the device FAILED and restarts (resets) it.
#include <chrono>
#include <optional>
#include <string>
#include <string_view>

#include "covtrack/devices/config_reader.hpp"

namespace covtrack {

// The [devices.<name>] key that sets the time. `doc` says what counts as a valid frame
// for this driver; both strings must outlive the spec (literals).
KeySpec no_valid_frames_key(std::string_view default_value, std::string_view doc);
inline constexpr std::string_view kNoValidFramesKey = "no_valid_frames_s";

class ValidFrameWatchdog {
 public:
  using Clock = std::chrono::steady_clock;
  // Counts from `start` as if a valid frame had arrived then.
  ValidFrameWatchdog(double limit_s, Clock::time_point start);

  void valid_frame(Clock::time_point now) { last_valid_ = now; }
  // "no valid frames for 3.0 s" once limit_s has passed without a valid frame.
  std::optional<std::string> expired(Clock::time_point now) const;

 private:
  Clock::duration limit_;
  double limit_s_;
  Clock::time_point last_valid_;
};

}  // namespace covtrack
