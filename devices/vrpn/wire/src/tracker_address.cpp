#include "covtrack/vrpn/tracker_address.hpp"

#include <algorithm>
#include <charconv>

#include <fmt/format.h>

#include "covtrack/vrpn/message_names.hpp"
#include "covtrack/vrpn/system_messages.hpp"

namespace covtrack::vrpn {
namespace {
bool host_character(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '-';
}
}  // namespace

Result<TrackerAddress> parse_tracker_address(std::string_view text) {
  const auto at = text.find('@');
  if (at == std::string_view::npos)
    return fail(fmt::format("'{}' is no VRPN device address: expected Name@host or Name@host:port", text));
  TrackerAddress a;
  a.name = std::string(text.substr(0, at));
  if (!is_valid_vrpn_name(a.name))
    return fail(fmt::format("'{}': the device name before '@' must be 1-{} printable ASCII characters", text,
                            kMaxVrpnNameLength));
  std::string_view rest = text.substr(at + 1);
  for (std::string_view scheme : {"tcp://", "x-vrpn://"})
    if (rest.starts_with(scheme)) rest.remove_prefix(scheme.size());
  a.port = kDefaultPort;
  if (const auto colon = rest.rfind(':'); colon != std::string_view::npos) {
    const std::string_view port = rest.substr(colon + 1);
    const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), a.port);
    if (ec != std::errc{} || end != port.data() + port.size() || a.port < 1 || a.port > 65535)
      return fail(fmt::format("'{}': the port after ':' must be 1-65535", text));
    rest = rest.substr(0, colon);
  }
  if (rest.empty() || !std::all_of(rest.begin(), rest.end(), host_character))
    return fail(fmt::format("'{}': the host after '@' must be a host name or an IPv4 address", text));
  a.host = std::string(rest);
  return a;
}

}  // namespace covtrack::vrpn
