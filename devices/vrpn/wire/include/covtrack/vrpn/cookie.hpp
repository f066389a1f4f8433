#pragma once
// The cookie each side of a VRPN connection sends first (docs/vrpn.md, "Handshake"):
// 24 bytes of ASCII, the version string, two spaces, the remote-logging digit, zeros.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "covtrack/protocol/result.hpp"

namespace covtrack::vrpn {

// The VRPN release whose wire format covtrack speaks. Peers of the same major version
// ("07") connect; a VRPN peer notes a minor difference on stderr and carries on.
inline constexpr std::string_view kVersion = "vrpn: ver. 07.38";
inline constexpr std::size_t kCookieSize = 24;
using Cookie = std::array<std::uint8_t, kCookieSize>;

// Ours asks the peer for no remote logging ('0').
Cookie make_cookie();

struct PeerCookie {
  std::string version;        // e.g. "vrpn: ver. 07.35"
  bool minor_differs = false;  // same major version, other minor: still compatible
  int log_mode = 0;           // 0-3: what the peer asks us to log (covtrack logs nothing)
};

// Checks a received cookie. The error quotes what arrived instead (printable bytes),
// so that a peer that is no VRPN server, or of another major version, is named as such.
Result<PeerCookie> check_cookie(std::span<const std::uint8_t> bytes);

}  // namespace covtrack::vrpn
