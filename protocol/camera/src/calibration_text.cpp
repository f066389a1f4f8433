#include "calibration_text.hpp"

#include <fmt/format.h>

namespace covtrack {

Result<void> check_calibration_text(std::string_view text) {
  if (text.size() > kMostCalibrationBytes)
    return fail(fmt::format("{} bytes, more than the {} a calibration file may have", text.size(),
                            kMostCalibrationBytes));
  int depth = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte == 0 || byte == 0xC0 || byte == 0xC1 || byte >= 0xF5)
      return fail(fmt::format("byte {} is 0x{:02X}, which no text file holds", i, byte));
    // Opening: '[', '{', and '<' starting an element; closing: ']', '}', "</" and "/>".
    const char next = i + 1 < text.size() ? text[i + 1] : '\0';
    const bool opens = byte == '[' || byte == '{' || (byte == '<' && next != '/' && next != '?' && next != '!');
    const bool closes = byte == ']' || byte == '}' || (byte == '<' && next == '/') || (byte == '/' && next == '>');
    if (opens && ++depth > kMostCalibrationNesting)
      return fail(fmt::format("nested more than {} deep at byte {}", kMostCalibrationNesting, i));
    if (closes && depth > 0) --depth;
  }
  return {};
}

}  // namespace covtrack
