#pragma once
// XpressNet framing between a PC and a Lenz interface (LI101F, LI-USB), as a pure
// stream decoder: bytes in, frames out, no clock and no I/O.
//
// A frame is HDR D1..Dn XOR: the header's low nibble is n, XOR is the XOR of every
// earlier byte. The LI-USB puts FF FE before replies and FF FD before unsolicited
// broadcasts; the LI101F sends no prefix. (docs/xpressnet.md, "Framing" and "USB interfaces")
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace covtrack::lenz {

enum class Prefix : std::uint8_t { None, Reply /* FF FE */, Unsolicited /* FF FD */ };

struct Frame {
  std::vector<std::uint8_t> bytes;  // header and data bytes, without the XOR byte
  Prefix prefix = Prefix::None;
  std::uint8_t header() const { return bytes.front(); }
  std::uint8_t opcode() const { return bytes.front() & 0xF0; }
};

// Header, data and XOR byte.
std::vector<std::uint8_t> encode_frame(std::span<const std::uint8_t> header_and_data);
// As above, with the LI-USB prefix in front (nothing for Prefix::None).
std::vector<std::uint8_t> encode_frame(std::span<const std::uint8_t> header_and_data, Prefix prefix);

struct FramingCounters {
  std::uint64_t frames = 0;
  std::uint64_t bad_frames = 0;     // runs of bytes that were not frames (bad XOR, stray headers)
  std::uint64_t skipped_bytes = 0;  // bytes dropped while looking for the next header
};

class FrameDecoder {
 public:
  // Appends bytes and returns every frame now complete. Bad frames are never returned:
  // they are counted and the decoder resynchronises on the next byte. A header still
  // waiting for its body is given up when a whole valid frame follows it in the input
  // (out of step, after garbage: anywhere; in step: ending with the input), so a good
  // frame takes effect when it arrives, not after later frames fill a stray header.
  std::vector<Frame> push(std::span<const std::uint8_t> bytes);
  const FramingCounters& counters() const { return counters_; }
  // Forget partial input (after a reconnect).
  void reset();

 private:
  std::optional<std::size_t> complete_frame_after(std::size_t pos) const;
  Prefix prefix_before(std::size_t header) const;

  std::vector<std::uint8_t> pending_;
  Prefix prefix_ = Prefix::None;
  bool in_sync_ = true;  // the last thing decoded was a frame (or nothing yet)
  FramingCounters counters_;
};

}  // namespace covtrack::lenz
