#pragma once
// Byte streams for the serial 6-DOF decoders' resync tests and benchmark: a long run of
// line noise (a unit at the wrong baud rate, a cable plugged in mid-stream) followed by
// valid records.
#include <cstddef>
#include <cstdint>
#include <iterator>

#include "record_encoder.hpp"

namespace covtrack::serial6dof::test {

// At least `size` bytes that no decoder can take for a record, but full of near misses:
// each protocol's header bytes followed, within the same token, by a byte that breaks the
// header, so that the decoders look closer at some positions instead of rejecting every
// byte at once. No byte has bit 7 set (it starts a Flock record); every token ends in a
// byte that starts no header, so tokens cannot combine into one.
inline Bytes noise_without_records(std::size_t size) {
  static const Bytes kTokens[] = {
      {'x'}, {'0', 'q'}, {'0', '3', '!'},  // Fastrak: bad station, bad status letter
      {'2', 'z'}, {'2', '5', 'z'},         // Fastrak status record: bad station, not 'S'
      {'L', 'x'}, {'P', '!'},              // Liberty: half a preamble
      {'M', 'M', 0x00, 'x'},               // Liberty: a preamble with station 0
      {0x11}, {0x7F}, {' '}, {'K'}};
  Bytes out;
  out.reserve(size + 4);
  std::uint32_t lcg = 12345;  // a fixed mix of tokens, not a periodic pattern
  while (out.size() < size) {
    lcg = lcg * 1664525u + 1013904223u;
    const Bytes& t = kTokens[(lcg >> 16) % std::size(kTokens)];
    out.insert(out.end(), t.begin(), t.end());
  }
  return out;
}

inline TrackerRecord stream_record(int i) {
  TrackerRecord r;
  r.station = 1 + i % 4;
  r.position_m = Vec3(0.1 + 0.001 * i, -0.2, 0.3);
  r.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * i, Vec3(1, 2, 3).normalized()));
  return r;
}

}  // namespace covtrack::serial6dof::test
