#include "covtrack/protocol/wire_text.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace covtrack {
namespace {

// The length of the well-formed UTF-8 sequence at `at` (RFC 3629), or 0.
std::size_t sequence_length(std::string_view s, std::size_t at) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned char b0 = byte(at);
  if (b0 < 0x80) return 1;
  std::size_t n = 0;
  unsigned char lo = 0x80, hi = 0xbf;  // the range of the second byte
  if (b0 >= 0xc2 && b0 <= 0xdf) n = 2;
  else if (b0 == 0xe0) n = 3, lo = 0xa0;               // no overlong 3-byte forms
  else if (b0 == 0xed) n = 3, hi = 0x9f;               // no surrogates
  else if (b0 >= 0xe1 && b0 <= 0xef) n = 3;
  else if (b0 == 0xf0) n = 4, lo = 0x90;               // no overlong 4-byte forms
  else if (b0 == 0xf4) n = 4, hi = 0x8f;               // nothing past U+10FFFF
  else if (b0 >= 0xf1 && b0 <= 0xf3) n = 4;
  else return 0;                                       // 80-C1, F5-FF never start one
  if (at + n > s.size()) return 0;
  if (byte(at + 1) < lo || byte(at + 1) > hi) return 0;
  for (std::size_t i = 2; i < n; ++i)
    if (byte(at + i) < 0x80 || byte(at + i) > 0xbf) return 0;
  return n;
}

bool is_control(std::string_view s, std::size_t at, std::size_t length) {
  const auto b0 = static_cast<unsigned char>(s[at]);
  if (length == 1) return b0 < 0x20 || b0 == 0x7f;
  return length == 2 && b0 == 0xc2 && static_cast<unsigned char>(s[at + 1]) <= 0x9f;  // U+0080-U+009F
}

}  // namespace

std::optional<std::size_t> invalid_utf8_at(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = sequence_length(text, i);
    if (n == 0) return i;
    i += n;
  }
  return std::nullopt;
}

std::optional<std::size_t> control_character_at(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = std::max<std::size_t>(1, sequence_length(text, i));
    if (is_control(text, i, n)) return i;
    i += n;
  }
  return std::nullopt;
}

std::string printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t n = sequence_length(text, i);
    if (n == 0 || is_control(text, i, n)) {
      for (std::size_t k = 0; k < std::max<std::size_t>(n, 1); ++k)
        out += fmt::format("\\x{:02x}", static_cast<unsigned char>(text[i + k]));
    } else if (text[i] == '\\') {
      out += "\\\\";
    } else {
      out.append(text.substr(i, n));
    }
    i += std::max<std::size_t>(n, 1);
  }
  return out;
}

}  // namespace covtrack
