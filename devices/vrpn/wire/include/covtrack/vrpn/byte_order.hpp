#pragma once
// VRPN sends every number in network order (big-endian): 32-bit integers and IEEE-754
// doubles (docs/vrpn.md). Written byte by byte, so the host's own order never matters.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace covtrack::vrpn {

inline void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(v >> shift));
}
inline void put_i32(std::vector<std::uint8_t>& out, std::int32_t v) { put_u32(out, static_cast<std::uint32_t>(v)); }
inline void put_f64(std::vector<std::uint8_t>& out, double v) {
  const auto bits = std::bit_cast<std::uint64_t>(v);
  put_u32(out, static_cast<std::uint32_t>(bits >> 32));
  put_u32(out, static_cast<std::uint32_t>(bits));
}

// Readers expect the caller to have checked that the bytes are there.
inline std::uint32_t get_u32(std::span<const std::uint8_t> in, std::size_t at) {
  return std::uint32_t{in[at]} << 24 | std::uint32_t{in[at + 1]} << 16 | std::uint32_t{in[at + 2]} << 8 |
         std::uint32_t{in[at + 3]};
}
inline std::int32_t get_i32(std::span<const std::uint8_t> in, std::size_t at) {
  return static_cast<std::int32_t>(get_u32(in, at));
}
inline double get_f64(std::span<const std::uint8_t> in, std::size_t at) {
  return std::bit_cast<double>(std::uint64_t{get_u32(in, at)} << 32 | get_u32(in, at + 4));
}

}  // namespace covtrack::vrpn
