#include "covtrack/vrpn/cookie.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace covtrack::vrpn {
namespace {
// The part of the version string that must match: up to and including its last period.
constexpr std::string_view kMajorPrefix = kVersion.substr(0, kVersion.rfind('.') + 1);
constexpr std::size_t kLogModeOffset = kVersion.size() + 2;

// What arrived, quotable in an error message.
std::string printable(std::span<const std::uint8_t> bytes) {
  std::string out;
  for (auto b : bytes) {
    if (b == 0) break;
    out += (b >= 0x20 && b < 0x7f) ? static_cast<char>(b) : '?';
  }
  return out;
}
}  // namespace

Cookie make_cookie() {
  Cookie c{};  // the bytes after the log digit stay zero
  std::copy(kVersion.begin(), kVersion.end(), c.begin());
  c[kVersion.size()] = ' ';
  c[kVersion.size() + 1] = ' ';
  c[kLogModeOffset] = '0';
  return c;
}

Result<PeerCookie> check_cookie(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kCookieSize)
    return fail(fmt::format("a VRPN cookie is {} bytes, got {}", kCookieSize, bytes.size()));
  const std::string version = printable(bytes.first(kVersion.size()));
  if (!std::equal(kMajorPrefix.begin(), kMajorPrefix.end(), bytes.begin()))
    return fail(fmt::format("not a VRPN peer of major version {}: it sent '{}' where VRPN sends '{}xx'",
                            kMajorPrefix.substr(kMajorPrefix.size() - 3, 2), printable(bytes.first(kCookieSize)),
                            kMajorPrefix));
  const std::uint8_t log = bytes[kLogModeOffset];
  if (log < '0' || log > '3')
    return fail(fmt::format("VRPN cookie '{}' has log mode byte 0x{:02x}, not '0'-'3'", version, log));
  PeerCookie out;
  out.version = version;
  out.minor_differs = !std::equal(kVersion.begin(), kVersion.end(), bytes.begin());
  out.log_mode = log - '0';
  return out;
}

}  // namespace covtrack::vrpn
