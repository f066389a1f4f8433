#pragma once
// Opening LCM without its silent failure modes: an unusable URL is reported at once,
// with how to fix it, instead of a ~10 s self-test hang on the first subscribe.
#include <netinet/in.h>

#include <memory>
#include <optional>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "covtrack/protocol/result.hpp"

namespace covtrack {

// The URL LCM would use: the argument if non-empty, else $LCM_DEFAULT_URL, else LCM's
// built-in default.
std::string effective_lcm_url(const std::string& url);

// Checks that the URL can work on this machine (for udpm: a route to the group).
Result<void> check_lcm_url(const std::string& url);

// A udpm:// URL: udpm://GROUP:PORT?ttl=N&recv_buf_size=BYTES, LCM's defaults where it
// names none. An option LCM does not know, or a value it could not use, is an error
// (LCM itself only warns and goes on).
struct UdpmUrl {
  sockaddr_in group{};                     // multicast group and port
  int ttl = 0;                             // 0-255: how many routers a sent datagram may cross
  std::optional<int> recv_buf_size;        // the socket receive buffer asked for, in bytes
};
Result<UdpmUrl> parse_udpm_url(const std::string& url);

// The group and port of a udpm:// URL.
Result<sockaddr_in> parse_udpm(const std::string& url);

// check_lcm_url, then create the instance.
Result<std::unique_ptr<lcm::LCM>> open_lcm(const std::string& url);

}  // namespace covtrack
