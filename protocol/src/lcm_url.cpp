#include "covtrack/protocol/lcm_url.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
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

}  // namespace

// udpm://GROUP:PORT?options -> the group and port; LCM's defaults where missing.
Result<sockaddr_in> parse_udpm(const std::string& url) {
  std::string rest = url.substr(std::strlen("udpm://"));
  rest = rest.substr(0, rest.find('?'));
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
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  if (inet_pton(AF_INET, host.c_str(), &addr.sin_addr) != 1)
    return fail("LCM URL '" + url + "': '" + host + "' is not an IPv4 address");
  if (!IN_MULTICAST(ntohl(addr.sin_addr.s_addr)))
    return fail("LCM URL '" + url + "': " + host + " is not a multicast group (224.0.0.0/4)");
  return addr;
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
