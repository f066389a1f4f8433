#pragma once
// The field order of each covtrack message on the wire, as lcm-gen encodes the
// definitions in protocol/lcmtypes/: what decode_message() walks before it lets LCM's
// decoder near the bytes. A change to a .lcm file must be made here too;
// tests/protocol/wire_decode_test.cpp fails until it is (a layout is checked against
// lcm-gen's fingerprint and encoder).
#include <cstdint>
#include <span>

namespace covtrack::wire {

enum class Kind : std::uint8_t {
  I8,
  I32,
  I64,
  F64,
  Name,   // string: a device or sensor name (channels.hpp's rules)
  Label,  // string: a frame, driver or encoding name: UTF-8 without control characters
  Text,   // string: free text (an error message): UTF-8
  Bytes,  // byte[n], n = the value of the I32 field just before it
};

struct Field {
  const char* name;
  Kind kind;
  int count = 1;  // fixed-size arrays of numbers
};

struct Layout {
  const char* type;
  std::uint64_t fingerprint;  // as lcm-gen computed it for this field list
  std::span<const Field> fields;
};

template <typename Msg>
const Layout& layout_of();

}  // namespace covtrack::wire
