#pragma once
// What a calibration file's text must be before OpenCV's reader sees it. OpenCV 4.6's
// FileStorage (Debian 12) has faults that a damaged file reaches and that no caller can
// catch: its YAML reader loops forever on a 0xFF byte (" -\xff\n-\n-" is enough), and its
// readers recurse once per nesting level without a limit, so a deep enough file
// overflows the stack. A calibration file is a few kilobytes of text nested a few levels.
#include <string>
#include <string_view>

#include "covtrack/protocol/result.hpp"

namespace covtrack {

inline constexpr std::size_t kMostCalibrationBytes = 1 << 20;
inline constexpr int kMostCalibrationNesting = 32;

// Whether `text` is within those limits: at most kMostCalibrationBytes; no NUL (OpenCV
// reads C strings) and no byte that text in UTF-8 never holds (0xC0, 0xC1, 0xF5-0xFF);
// lists, maps and XML elements nested at most kMostCalibrationNesting deep. The error
// says which and where (byte offset).
Result<void> check_calibration_text(std::string_view text);

}  // namespace covtrack
