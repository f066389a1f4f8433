#pragma once
// A decoder's error result: the fault and what was wrong, for its std::expected. Shared by
// the sources that check wire messages and the ones that check datagrams.
#include <expected>
#include <string>
#include <utility>

#include "covtrack/protocol/lcm_datagram.hpp"
#include "covtrack/protocol/wire_decode.hpp"

namespace covtrack {

inline std::unexpected<WireRejection> reject(WireFault fault, std::string detail) {
  return std::unexpected(WireRejection{fault, std::move(detail)});
}

namespace lcm_wire {
inline std::unexpected<DatagramRejection> reject(DatagramFault fault, std::string detail) {
  return std::unexpected(DatagramRejection{fault, std::move(detail)});
}
}  // namespace lcm_wire

}  // namespace covtrack
