#include "covtrack/protocol/lcm_url.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

namespace covtrack {
namespace {
constexpr const char* kLcmDefaultUrl = "udpm://239.255.76.67:7667?ttl=0";

std::string fix_hint() {
  return "To keep LCM on this machine, add a multicast route through loopback:\n"
         "    sudo ip link set lo multicast on && sudo ip route add 224.0.0.0/4 dev lo\n"
         "or pass another URL with --lcm-url (for example memq:// inside one process).";
}

// The value of option `key` as an integer in [low, high].
Result<int> option_value(const std::string& url, const std::string& key, const std::string& text, long low,
                         long high) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 0);  // base 0, as LCM reads it
  if (text.empty() || *end != '\0' || errno != 0 || v < low || v > high)
    return fail("LCM URL '" + url + "': " + key + "='" + text + "' is not an integer in " + std::to_string(low) +
                "-" + std::to_string(high));
  return static_cast<int>(v);
}

Result<void> parse_option(const std::string& url, const std::string& option, UdpmUrl& out) {
  const auto eq = option.find('=');
  const std::string key = option.substr(0, eq);
  const std::string value = eq == std::string::npos ? "" : option.substr(eq + 1);
  if (key == "transmit_only") return {};  // obsolete in LCM, which ignores it
  if (key == "ttl") {
    auto v = option_value(url, key, value, 0, 255);
    if (!v) return std::unexpected(v.error());
    out.ttl = *v;
  } else if (key == "recv_buf_size") {
    auto v = option_value(url, key, value, 1, INT_MAX);
    if (!v) return std::unexpected(v.error());
    out.recv_buf_size = *v;
  } else {
    return fail("LCM URL '" + url + "': unknown option '" + key + "' (udpm takes ttl and recv_buf_size)");
  }
  return {};
}
}  // namespace

Result<UdpmUrl> parse_udpm_url(const std::string& url) {
  std::string rest = url.substr(std::strlen("udpm://"));
  const auto question = rest.find('?');
  const std::string options = question == std::string::npos ? "" : rest.substr(question + 1);
  rest = rest.substr(0, question);
  std::string host = "239.255.76.67";
  int port = 7667;
  if (!rest.empty()) {
    const auto colon = rest.find(':');
    host = rest.substr(0, colon);
    if (colon != std::string::npos) {
      char* end = nullptr;
      const long p = std::strtol(rest.c_str() + colon + 1, &end, 10);
      if (*end != '\0' || p <= 0 || p > 65535)
        return fail("LCM URL '" + url + "': port '" + rest.substr(colon + 1) + "' is not 1-65535");
      port = static_cast<int>(p);
    }
  }
  UdpmUrl out;
  out.group.sin_family = AF_INET;
  out.group.sin_port = htons(static_cast<uint16_t>(port));
  if (inet_pton(AF_INET, host.c_str(), &out.group.sin_addr) != 1)
    return fail("LCM URL '" + url + "': '" + host + "' is not an IPv4 address");
  if (!IN_MULTICAST(ntohl(out.group.sin_addr.s_addr)))
    return fail("LCM URL '" + url + "': " + host + " is not a multicast group (224.0.0.0/4)");
  for (std::size_t at = 0; at < options.size();) {
    const auto amp = std::min(options.find('&', at), options.size());
    if (amp > at)
      if (auto ok = parse_option(url, options.substr(at, amp - at), out); !ok) return std::unexpected(ok.error());
    at = amp + 1;
  }
  return out;
}

Result<sockaddr_in> parse_udpm(const std::string& url) {
  auto parsed = parse_udpm_url(url);
  if (!parsed) return std::unexpected(parsed.error());
  return parsed->group;
}

std::string effective_lcm_url(const std::string& url) {
  if (!url.empty()) return url;
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return env;
  return kLcmDefaultUrl;
}

Result<void> check_lcm_url(const std::string& given) {
  const std::string url = effective_lcm_url(given);
  if (!url.starts_with("udpm://")) return {};  // memq, file, tcpq: nothing to route
  auto addr = parse_udpm(url);
  if (!addr) return std::unexpected(addr.error());

  // A connect() on a UDP socket only asks the kernel for a route; no packet is sent.
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return fail(std::string("cannot create a UDP socket: ") + std::strerror(errno));
  const int rc = ::connect(fd, reinterpret_cast<const sockaddr*>(&*addr), sizeof(*addr));
  const int err = errno;
  ::close(fd);
  if (rc != 0)
    return fail("LCM URL '" + url + "' is unusable: no route to its multicast group (" +
                std::strerror(err) + "). LCM would stall ~10 s in its self-test.\n" + fix_hint());
  return {};
}

Result<std::unique_ptr<lcm::LCM>> open_lcm(const std::string& given) {
  const std::string url = effective_lcm_url(given);
  if (auto ok = check_lcm_url(url); !ok) return std::unexpected(ok.error());
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) return fail("LCM could not open '" + url + "' (see LCM's message above)");
  return lcm;
}

}  // namespace covtrack
