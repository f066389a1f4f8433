#pragma once
// Text that came from the wire: whether it is UTF-8, whether it holds control characters
// (which a terminal would obey and JSON must escape), and a form safe to print.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace covtrack {

// The byte offset of the first byte that does not start or continue a well-formed UTF-8
// sequence (overlong forms, surrogates and code points past U+10FFFF are not), or nothing.
std::optional<std::size_t> invalid_utf8_at(std::string_view text);

// The byte offset of the first control character: C0 (below U+0020), DEL or C1
// (U+0080-U+009F), or nothing. `text` must be valid UTF-8.
std::optional<std::size_t> control_character_at(std::string_view text);

// `text` with every control character and every byte of an invalid sequence written as
// \xNN, and backslashes doubled: one line, safe on a terminal and in any log.
std::string printable(std::string_view text);

}  // namespace covtrack
