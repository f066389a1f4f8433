#pragma once
// VRPN's message framing (docs/vrpn.md, "Messages"): a 24-byte header of big-endian
// 32-bit words (length, seconds, microseconds, sender, type, and a word receivers
// skip), then the payload, zero-padded to a multiple of 8 bytes. The length counts the
// header and the payload without its padding. Pure: bytes in, messages out.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "covtrack/protocol/result.hpp"

namespace covtrack::vrpn {

inline constexpr std::size_t kAlignment = 8;
inline constexpr std::size_t kHeaderSize = 24;
// A VRPN receiver reads a message into a buffer of this many bytes; larger is an error.
inline constexpr std::size_t kMaxPaddedPayload = 64000;
// The largest UDP datagram VRPN sends (an Ethernet frame's worth).
inline constexpr std::size_t kMaxDatagram = 1472;

constexpr std::size_t padded(std::size_t size) { return (size + kAlignment - 1) / kAlignment * kAlignment; }

struct Message {
  std::int32_t sender = 0;  // the sending side's id, described by a sender description
  std::int32_t type = 0;    // the sending side's id, or a system type (< 0)
  std::int64_t time_us = 0;  // seconds and microseconds since the Unix epoch on the wire
  std::vector<std::uint8_t> payload;
};

// Appends the framed message. `sequence` fills the header's last word, which VRPN
// writes for packet sniffers and no receiver reads.
void append_message(std::vector<std::uint8_t>& out, const Message& message, std::uint32_t sequence);

// One message from the front of `bytes`, and how many bytes it took (header, payload
// and padding); nothing while the bytes hold only part of it. An error for a header no
// VRPN sender writes (a length below the header, a payload beyond kMaxPaddedPayload).
struct Decoded {
  Message message;
  std::size_t consumed = 0;
};
Result<std::optional<Decoded>> decode_message(std::span<const std::uint8_t> bytes);

// Every message of one UDP datagram (VRPN packs several into one); a datagram that ends
// inside a message is an error.
Result<std::vector<Message>> decode_datagram(std::span<const std::uint8_t> datagram);

}  // namespace covtrack::vrpn
