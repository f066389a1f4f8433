#pragma once
// What a calibration file's text must be before a YAML or XML reader sees it. A
// calibration file is a few kilobytes of text nested a few levels: a binary file given by
// mistake (an image, a compressed file) is named as such, at the first byte no text holds,
// instead of as a parse error somewhere in it, and a file nested deeper than any
// calibration is refused before a reader recurses into it.
#include <string>
#include <string_view>

#include "covtrack/protocol/result.hpp"

namespace covtrack {

inline constexpr std::size_t kMostCalibrationBytes = 1 << 20;
inline constexpr int kMostCalibrationNesting = 32;

// Whether `text` is within those limits: at most kMostCalibrationBytes; no NUL and no
// byte that text in UTF-8 never holds (0xC0, 0xC1, 0xF5-0xFF); lists, maps and XML
// elements nested at most kMostCalibrationNesting deep. The error
// says which and where (byte offset).
Result<void> check_calibration_text(std::string_view text);

}  // namespace covtrack
