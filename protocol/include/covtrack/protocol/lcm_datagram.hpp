#pragma once
// LCM's UDP multicast wire format, read from one datagram without trusting it.
//
// Every integer is big-endian. A message whose channel, NUL and payload fit in 65,499
// bytes travels as one datagram:
//   "LC02" | sequence u32 | channel, NUL | payload
// A larger one is cut into fragments, one datagram each, sent in order:
//   "LC03" | sequence u32 | message size u32 | offset u32 | fragment number u16 |
//   fragment count u16 | (fragment 0 only: channel, NUL) | data
// where the offset is that of the data within the payload (the channel not counted) and
// the sequence number counts the sender's messages. Channel names are at most 63 bytes.
// lcm_reassembly.hpp puts fragments back together.
#include <cstddef>
#include <cstdint>
#include <expected>
#include <span>
#include <string>
#include <string_view>
#include <variant>

namespace covtrack::lcm_wire {

constexpr std::uint32_t kShortMagic = 0x4c433032;     // "LC02"
constexpr std::uint32_t kFragmentMagic = 0x4c433033;  // "LC03"
constexpr std::size_t kShortHeaderBytes = 8;
constexpr std::size_t kFragmentHeaderBytes = 20;
constexpr std::size_t kMaxChannelBytes = 63;
constexpr std::size_t kMaxDatagramBytes = 65535;

struct ShortMessage {
  std::uint32_t sequence;
  std::string_view channel;
  std::span<const std::byte> payload;
};

struct Fragment {
  std::uint32_t sequence;
  std::uint32_t message_size;  // of the whole payload
  std::uint32_t offset;        // of `data` within the payload
  std::uint16_t number;        // 0 .. count - 1
  std::uint16_t count;
  std::string_view channel;    // fragment 0 only; empty in the others
  std::span<const std::byte> data;
};

using Datagram = std::variant<ShortMessage, Fragment>;

enum class DatagramFault {
  Truncated,           // shorter than its header
  BadMagic,            // neither "LC02" nor "LC03"
  BadChannel,          // no NUL ends the channel, or it is longer than 63 bytes
  BadFragmentNumber,   // a fragment count of 0, or a number not below the count
  FragmentOutOfBounds, // data past the message size, or fragment 0 not at offset 0
  TooLarge,            // a message larger than the receiver's bound (lcm_reassembly.hpp)
  Inconsistent,        // a fragment disagreeing with the earlier ones of its message
  Duplicate,           // a fragment received twice
};
const char* to_string(DatagramFault fault);

struct DatagramRejection {
  DatagramFault fault;
  std::string detail;  // the values that are wrong
  std::string describe() const { return std::string(to_string(fault)) + ": " + detail; }
};

// The datagram's header fields and where its channel and data lie (views into `bytes`).
std::expected<Datagram, DatagramRejection> decode_datagram(std::span<const std::byte> bytes);

}  // namespace covtrack::lcm_wire
