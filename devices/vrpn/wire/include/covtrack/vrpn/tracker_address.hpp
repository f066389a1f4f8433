#pragma once
// A VRPN device address as VRPN's tools take it: "Tracker0@host" or
// "Tracker0@host:port" (port 3883 when none is given); a "tcp://" or "x-vrpn://" before
// the host is accepted, as covtrack always connects over TCP.
#include <string>
#include <string_view>

#include "covtrack/protocol/result.hpp"

namespace covtrack::vrpn {

struct TrackerAddress {
  std::string name;  // the device's sender name, before the '@'
  std::string host;  // a host name or dotted IPv4 address
  int port = 0;

  std::string endpoint() const { return host + ":" + std::to_string(port); }  // "host:3883"
  std::string text() const { return name + "@" + endpoint(); }               // "Tracker0@host:3883"
};

// The error says what part is wrong, quoting the text.
Result<TrackerAddress> parse_tracker_address(std::string_view text);

}  // namespace covtrack::vrpn
