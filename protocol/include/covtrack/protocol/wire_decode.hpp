#pragma once
// Decoding messages that come from the wire or from a log, which nothing vouches for.
//
// LCM 1.3's generated C++ decoder trusts the bytes: a string length of 0 or less makes it
// throw std::length_error (the process ends), an array length makes it allocate before it
// checks the size. Every covtrack program decodes through here instead: the bytes are
// walked field by field first (type fingerprint, every string and array length inside the
// message, nothing after the last field but an authentication trailer (message_auth.hpp,
// not checked here), names and text by their rules), and only then
// handed to LCM's decoder, whose failures are caught as well. A message that passes
// holds only valid UTF-8, so JSON and terminals can take its strings as they are. A message that fails is rejected with a fault and a
// detail saying which field, where; protocol/README.md, "Receiving", lists the checks.
#include <cstddef>
#include <expected>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <covtrack/device_claim_t.hpp>
#include <covtrack/device_status_t.hpp>
#include <covtrack/image_t.hpp>
#include <covtrack/pose_cov_t.hpp>
#include <covtrack/raw_bytes_t.hpp>
#include <covtrack/truth_pose_t.hpp>

namespace covtrack {

enum class WireFault {
  Truncated,      // the bytes end inside a field
  WrongType,      // the fingerprint is not the type the channel carries
  BadLength,      // a string or array length that is negative, zero for a string, or past the end
  TrailingBytes,  // bytes after the last field
  BadName,        // a device or sensor name that breaks the naming rules (channels.hpp)
  BadText,        // a string that is not UTF-8, or a frame, driver or encoding name with a control character
  DecoderFailed,  // LCM's decoder refused or threw (after the walk found nothing)
  BadValue,       // a heartbeat or claim field out of its range (state, rate, period, stage)
  BadChannel,     // a covtrack channel whose name breaks the rules (protocol/README.md, "Messages")
  WrongChannel,   // the message names another device or sensor than its channel
};
const char* to_string(WireFault fault);

struct WireRejection {
  WireFault fault;
  std::string detail;  // the field and byte offset, or the values that disagree
  std::string describe() const { return std::string(to_string(fault)) + ": " + detail; }
};

template <typename Msg>
using Decoded = std::expected<Msg, WireRejection>;

// One of the six covtrack message types, checked as above.
template <typename Msg>
Decoded<Msg> decode_message(std::span<const std::byte> bytes);

inline std::span<const std::byte> bytes_of(const void* data, std::size_t size) {
  return {static_cast<const std::byte*>(data), size};
}

}  // namespace covtrack
