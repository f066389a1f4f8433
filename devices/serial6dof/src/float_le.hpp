#pragma once
// Little-endian fields of the Polhemus binary formats (Intel byte order, IEEE-754 floats).
#include <bit>
#include <cstdint>

namespace covtrack::serial6dof {

inline std::uint32_t read_u32_le(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
inline std::uint16_t read_u16_le(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | p[1] << 8);
}
inline double read_float_le(const std::uint8_t* p) {
  return static_cast<double>(std::bit_cast<float>(read_u32_le(p)));
}

}  // namespace covtrack::serial6dof
