// UTF-8 and control characters in text from the wire, against sequences whose verdict
// RFC 3629 states.
#include <gtest/gtest.h>

#include "covtrack/protocol/wire_text.hpp"

using namespace covtrack;

TEST(WireText, WellFormedUtf8IsAccepted) {
  for (const char* s : {"", "world", "caf\xc3\xa9", "\xe2\x82\xac 5", "\xf0\x9f\x98\x80", "\xf4\x8f\xbf\xbf",
                        "\xed\x9f\xbf", "\xef\xbf\xbd"})
    EXPECT_FALSE(invalid_utf8_at(s)) << printable(s);
}

TEST(WireText, EachMalformedSequenceIsFoundAtItsFirstByte) {
  const std::pair<std::string, std::size_t> cases[] = {
      {"ab\xff", 2},              // never a UTF-8 byte
      {"a\x80", 1},               // a continuation byte alone
      {"\xc0\xaf", 0},            // overlong '/'
      {"\xe0\x80\xaf", 0},        // overlong, 3 bytes
      {"\xf0\x80\x80\xaf", 0},    // overlong, 4 bytes
      {"x\xed\xa0\x80", 1},       // a UTF-16 surrogate
      {"\xf4\x90\x80\x80", 0},    // past U+10FFFF
      {"ok\xe2\x82", 2},          // cut short
      {"\xc3(", 0},               // continuation missing
  };
  for (const auto& [text, at] : cases) {
    const auto found = invalid_utf8_at(text);
    ASSERT_TRUE(found) << printable(text);
    EXPECT_EQ(*found, at) << printable(text);
  }
}

TEST(WireText, ControlCharactersAreC0DelAndC1) {
  EXPECT_FALSE(control_character_at("head tracker \xc3\xa9"));
  EXPECT_EQ(control_character_at("a\x1b[2J"), 1u);
  EXPECT_EQ(control_character_at("ab\x7f"), 2u);
  EXPECT_EQ(control_character_at("\xc3\xa9\xc2\x9b"), 2u);  // U+009B, the 8-bit CSI
  EXPECT_EQ(control_character_at(std::string("a\0b", 3)), 1u);
  EXPECT_EQ(control_character_at("line\n"), 4u);
}

TEST(WireText, PrintableEscapesWhatATerminalWouldObey) {
  EXPECT_EQ(printable("caf\xc3\xa9"), "caf\xc3\xa9");
  EXPECT_EQ(printable("a\x1b[2Jb"), "a\\x1b[2Jb");
  EXPECT_EQ(printable("x\xff\xc0"), "x\\xff\\xc0");
  EXPECT_EQ(printable("\xc2\x9b"), "\\xc2\\x9b");
  EXPECT_EQ(printable("a\\x1b"), "a\\\\x1b");  // a literal backslash is not taken for an escape
  EXPECT_FALSE(invalid_utf8_at(printable("\xfe\xed\xa0\x80")));
}
