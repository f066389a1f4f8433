#include "covtrack/vrpn/system_messages.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "covtrack/vrpn/byte_order.hpp"

namespace covtrack::vrpn {
namespace {
bool is_printable(char c) { return c >= 0x20 && c < 0x7f; }
}  // namespace

bool is_valid_vrpn_name(std::string_view name) {
  return !name.empty() && name.size() <= kMaxVrpnNameLength && std::all_of(name.begin(), name.end(), is_printable);
}

std::vector<std::uint8_t> name_description(std::string_view name) {
  std::vector<std::uint8_t> out;
  put_u32(out, static_cast<std::uint32_t>(name.size() + 1));
  out.insert(out.end(), name.begin(), name.end());
  out.push_back(0);
  return out;
}

Result<std::string> parse_name_description(std::span<const std::uint8_t> payload) {
  if (payload.size() < 5 || payload.size() > 4 + kMaxVrpnNameLength + 1)
    return fail(fmt::format("VRPN name description of {} bytes (5-{} expected)", payload.size(),
                            4 + kMaxVrpnNameLength + 1));
  const std::uint32_t with_nul = get_u32(payload, 0);
  if (with_nul < 2 || with_nul > payload.size() - 4)
    return fail(fmt::format("VRPN name description gives a length of {} in {} bytes", with_nul, payload.size()));
  std::string name(payload.begin() + 4, payload.begin() + 4 + (with_nul - 1));
  // A peer's names are only compared, never shown whole: any bytes but NUL will do.
  if (payload[4 + with_nul - 1] != 0 || name.find('\0') != std::string::npos)
    return fail("VRPN name description holds a name that is not NUL-terminated where its length says");
  return name;
}

std::vector<std::uint8_t> udp_description(std::string_view host) {
  std::vector<std::uint8_t> out(host.begin(), host.end());
  out.push_back(0);
  return out;
}

Result<std::string> parse_udp_description(std::span<const std::uint8_t> payload) {
  const auto nul = std::find(payload.begin(), payload.end(), std::uint8_t{0});
  std::string host(payload.begin(), nul);
  if (nul == payload.end() || host.empty() || host.size() > 255 || !std::all_of(host.begin(), host.end(), is_printable))
    return fail("VRPN UDP description holds no NUL-terminated host name");
  return host;
}

}  // namespace covtrack::vrpn
