#pragma once
// VRPN's system messages (negative type ids; docs/vrpn.md, "System messages"): how each
// side tells the other the names behind its sender and type ids, and where it takes UDP.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "covtrack/protocol/result.hpp"

namespace covtrack::vrpn {

enum SystemType : std::int32_t {
  kSenderDescription = -1,  // sender field: the id described; payload: its name
  kTypeDescription = -2,    // likewise for a message type
  kUdpDescription = -3,     // sender field: a UDP port; payload: the host, NUL-terminated
  kLogDescription = -4,     // a request to log on the receiver's side (covtrack ignores it)
  kDisconnect = -5,         // written into VRPN's log files only, never sent
};

// A VRPN receiver copies a name description into 100 bytes: the 4-byte length, the
// name and its NUL must fit, so a name has at most 95 characters.
inline constexpr std::size_t kMaxVrpnNameLength = 95;

// Sender and type names as covtrack writes them: 1-95 printable ASCII characters.
// (VRPN's own type names hold spaces: "vrpn_Tracker Pos_Quat".)
bool is_valid_vrpn_name(std::string_view name);

// The payload of a sender or type description: the name's length with its NUL as a
// big-endian 32-bit integer, then the name and the NUL.
std::vector<std::uint8_t> name_description(std::string_view name);
Result<std::string> parse_name_description(std::span<const std::uint8_t> payload);

// The payload of a UDP description: the host (a dotted IPv4 address) and a NUL.
std::vector<std::uint8_t> udp_description(std::string_view host);
Result<std::string> parse_udp_description(std::span<const std::uint8_t> payload);

}  // namespace covtrack::vrpn
