#include "covtrack/devices/valid_frame_watchdog.hpp"

#include <fmt/format.h>

namespace covtrack {

KeySpec no_valid_frames_key(std::string_view default_value, std::string_view doc) {
  return {kNoValidFramesKey, ValueType::Float, "s", default_value, doc, 0.1, 3600};
}

ValidFrameWatchdog::ValidFrameWatchdog(double limit_s, Clock::time_point start)
    : limit_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(limit_s))),
      limit_s_(limit_s),
      last_valid_(start) {}

std::optional<std::string> ValidFrameWatchdog::expired(Clock::time_point now) const {
  if (now - last_valid_ < limit_) return std::nullopt;
  return fmt::format("no valid frames for {:.1f} s", limit_s_);
}

}  // namespace covtrack
