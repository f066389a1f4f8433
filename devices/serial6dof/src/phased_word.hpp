#pragma once
// The 14-bit "phasing" words of the Flock of Birds (and IS-900 items 18-20): each 16-bit
// value keeps its top 14 bits, sent LS byte first, 7 bits per byte; only the first byte
// of a record has bit 7 set (laserBIRD guide).
#include <cstdint>

namespace covtrack::serial6dof {

inline std::int16_t decode_phased_word(std::uint8_t ls, std::uint8_t ms) {
  const auto raw = static_cast<std::uint16_t>(((ls & 0x7F) << 2) | ((ms & 0x7F) << 9));
  return static_cast<std::int16_t>(raw);
}

// The inverse, for emulators and tests; `first` sets the phasing bit.
inline void encode_phased_word(std::int16_t value, bool first, std::uint8_t out[2]) {
  const auto raw = static_cast<std::uint16_t>(value);
  out[0] = static_cast<std::uint8_t>(((raw >> 2) & 0x7F) | (first ? 0x80 : 0));
  out[1] = static_cast<std::uint8_t>((raw >> 9) & 0x7F);
}

}  // namespace covtrack::serial6dof
