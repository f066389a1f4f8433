#include "covtrack/protocol/wire_decode.hpp"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <exception>

#include <fmt/format.h>

#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/message_auth.hpp"
#include "covtrack/protocol/wire_text.hpp"
#include "rejection.hpp"
#include "wire_layout.hpp"

namespace covtrack {

const char* to_string(WireFault fault) {
  switch (fault) {
    case WireFault::Truncated: return "truncated";
    case WireFault::WrongType: return "wrong type";
    case WireFault::BadLength: return "bad length";
    case WireFault::TrailingBytes: return "trailing bytes";
    case WireFault::BadName: return "bad name";
    case WireFault::BadText: return "bad text";
    case WireFault::DecoderFailed: return "decoder failed";
    case WireFault::BadValue: return "bad value";
    case WireFault::BadChannel: return "bad channel";
    case WireFault::WrongChannel: return "wrong channel";
  }
  return "?";
}

namespace {

using wire::Field;
using wire::Kind;

// Big-endian integers at a cursor that never reads past the end.
class Cursor {
 public:
  explicit Cursor(std::span<const std::byte> bytes) : bytes_(bytes) {}
  std::size_t offset() const { return pos_; }
  std::size_t left() const { return bytes_.size() - pos_; }
  std::uint64_t read(int size) {  // call only when left() >= size
    std::uint64_t v = 0;
    for (int i = 0; i < size; ++i) v = (v << 8) | std::to_integer<std::uint64_t>(bytes_[pos_++]);
    return v;
  }
  void skip(std::size_t n) { pos_ += n; }

 private:
  std::span<const std::byte> bytes_;
  std::size_t pos_ = 0;
};

int element_size(Kind kind) {
  switch (kind) {
    case Kind::I8: return 1;
    case Kind::I32: return 4;
    default: return 8;
  }
}

bool is_string(Kind kind) { return kind == Kind::Name || kind == Kind::Label || kind == Kind::Text; }

// What is wrong with a string field's text, by its kind of field.
std::optional<std::pair<WireFault, std::string>> check_text(const Field& f, std::string_view text) {
  if (f.kind == Kind::Name) {
    if (is_valid_name(text)) return std::nullopt;
    return std::pair{WireFault::BadName, fmt::format("'{}' is not 1-{} characters of A-Z a-z 0-9 _ -",
                                                     printable(text), kMaxNameLength)};
  }
  if (const auto at = invalid_utf8_at(text))
    return std::pair{WireFault::BadText, fmt::format("'{}' is not UTF-8 (at its byte {})", printable(text), *at)};
  if (f.kind == Kind::Label)
    if (const auto at = control_character_at(text))
      return std::pair{WireFault::BadText,
                       fmt::format("'{}' holds a control character (at its byte {})", printable(text), *at)};
  return std::nullopt;
}

// A string field's bytes (`body`, its NUL included) that start at byte `at`. LCM strings
// are C strings: the first NUL must be the last byte, or the message would decode to
// another string than the one it re-encodes to.
std::expected<void, WireRejection> check_string(const Field& f, std::span<const std::byte> body, std::size_t at) {
  const auto nul = std::find(body.begin(), body.end(), std::byte{0});
  if (nul != body.end() - 1)
    return reject(WireFault::BadLength,
                  fmt::format("string '{}' at byte {}: length {}, but its first NUL is {}", f.name, at, body.size(),
                              nul == body.end() ? "missing" : fmt::format("its byte {}", nul - body.begin())));
  const std::string_view text(reinterpret_cast<const char*>(body.data()), body.size() - 1);
  if (auto bad = check_text(f, text))
    return reject(bad->first, fmt::format("string '{}' at byte {}: {}", f.name, at, bad->second));
  return {};
}

// Walks the fields as lcm-gen encodes them; every length is checked against what is left.
// Returns where the message ends: the size of the bytes, or where an authentication
// trailer (message_auth.hpp) after the last field starts.
std::expected<std::size_t, WireRejection> walk(const wire::Layout& layout, std::span<const std::byte> bytes) {
  Cursor c(bytes);
  if (c.left() < 8)
    return reject(WireFault::Truncated, fmt::format("{} bytes: shorter than the 8-byte type fingerprint", bytes.size()));
  if (const std::uint64_t fingerprint = c.read(8); fingerprint != layout.fingerprint)
    return reject(WireFault::WrongType, fmt::format("fingerprint {:016x} is not {}'s ({:016x})", fingerprint,
                                                    layout.type, layout.fingerprint));
  std::int64_t last_int32 = 0;  // the length of a byte array that follows
  for (const Field& f : layout.fields) {
    const std::size_t at = c.offset();
    if (is_string(f.kind)) {
      if (c.left() < 4)
        return reject(WireFault::Truncated, fmt::format("string '{}' at byte {}: its length is cut off", f.name, at));
      const std::int64_t length = static_cast<std::int32_t>(c.read(4));
      // LCM counts a string's NUL: 0 or less is no string (and made LCM's decoder throw).
      if (length <= 0 || static_cast<std::uint64_t>(length) > c.left())
        return reject(WireFault::BadLength,
                      fmt::format("string '{}' at byte {}: length {}, {} bytes left", f.name, at, length, c.left()));
      if (auto bad = check_string(f, bytes.subspan(c.offset(), static_cast<std::size_t>(length)), at); !bad)
        return std::unexpected(bad.error());
      c.skip(static_cast<std::size_t>(length));
    } else if (f.kind == Kind::Bytes) {
      if (last_int32 < 0 || static_cast<std::uint64_t>(last_int32) > c.left())
        return reject(WireFault::BadLength,
                      fmt::format("array '{}' at byte {}: length {}, {} bytes left", f.name, at, last_int32, c.left()));
      c.skip(static_cast<std::size_t>(last_int32));
    } else {
      const std::size_t size = static_cast<std::size_t>(element_size(f.kind)) * f.count;
      if (c.left() < size)
        return reject(WireFault::Truncated,
                      fmt::format("field '{}' at byte {}: needs {} bytes, {} left", f.name, at, size, c.left()));
      if (f.kind == Kind::I32) last_int32 = static_cast<std::int32_t>(c.read(4));
      else c.skip(size);
    }
  }
  if (c.left() > 0 && !is_auth_trailer(bytes.subspan(c.offset())))
    return reject(WireFault::TrailingBytes, fmt::format("{} bytes after the last field of {} (at byte {})", c.left(),
                                                        layout.type, c.offset()));
  return c.offset();
}

}  // namespace

template <typename Msg>
Decoded<Msg> decode_message(std::span<const std::byte> bytes) {
  if (bytes.size() > static_cast<std::size_t>(INT_MAX))
    return reject(WireFault::BadLength, fmt::format("{} bytes: more than LCM's decoder takes", bytes.size()));
  const auto walked = walk(wire::layout_of<Msg>(), bytes);
  if (!walked) return std::unexpected(walked.error());
  Msg msg;
  const int size = static_cast<int>(*walked);
  try {  // the walk leaves nothing for it to throw on; this is the second line of defence
    if (const int n = msg.decode(bytes.data(), 0, size); n != size)
      return reject(WireFault::DecoderFailed, fmt::format("LCM's decoder returned {} for {} bytes", n, size));
  } catch (const std::exception& e) {
    return reject(WireFault::DecoderFailed, fmt::format("LCM's decoder threw: {}", e.what()));
  }
  return msg;
}

template Decoded<pose_cov_t> decode_message(std::span<const std::byte>);
template Decoded<truth_pose_t> decode_message(std::span<const std::byte>);
template Decoded<device_status_t> decode_message(std::span<const std::byte>);
template Decoded<device_claim_t> decode_message(std::span<const std::byte>);
template Decoded<raw_bytes_t> decode_message(std::span<const std::byte>);
template Decoded<image_t> decode_message(std::span<const std::byte>);

}  // namespace covtrack
