// decode_message() and the channel checks against real lcm-gen encodings: every valid
// message passes unchanged, and every way the bytes can lie (the cases that ended covtrack
// clients: string lengths of 0 or less, huge arrays, wrong types, truncation, bit flips)
// is rejected with its fault, never thrown.
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "covtrack/protocol/channel_messages.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/pose_message.hpp"
#include "covtrack/protocol/wire_decode.hpp"
#include "covtrack/protocol/wire_text.hpp"
#include "wire_layout.hpp"  // protocol/src: the layouts are internal

using namespace covtrack;

namespace {

template <typename Msg>
std::vector<std::byte> encode(const Msg& m) {
  std::vector<std::byte> out(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(out.data(), 0, static_cast<int>(out.size())), static_cast<int>(out.size()));
  return out;
}

pose_cov_t pose(const std::string& device = "dev", const std::string& sensor = "head") {
  pose_cov_t m{};
  m.device = device;
  m.sensor = sensor;
  m.parent_frame = "world";
  m.child_frame = sensor;
  m.sequence = 42;
  set_pose(m, Pose::Identity(), Mat6::Identity() * 1e-6);
  return m;
}

device_status_t status(const std::string& device = "dev") {
  device_status_t s{};
  s.device = device;
  s.driver = "sim";
  s.last_error = "";
  s.detail = "no tag in view";
  s.instance_id = 0x1234567890abcdef;
  s.host = "lab-pc";
  s.pid = 4242;
  s.heartbeat_period_us = 1'000'000;
  return s;
}

raw_bytes_t raw(std::size_t n) {
  raw_bytes_t r{};
  r.device = "dev";
  r.length = static_cast<std::int32_t>(n);
  for (std::size_t i = 0; i < n; ++i) r.data.push_back(static_cast<std::uint8_t>(i));
  return r;
}

image_t image() {
  image_t m{};
  m.device = "cam";
  m.width = 2;
  m.height = 1;
  m.encoding = "png";
  m.size = 3;
  m.data = {1, 2, 3};
  return m;
}

void put_int32(std::vector<std::byte>& b, std::size_t at, std::int32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = std::byte((static_cast<std::uint32_t>(v) >> (24 - 8 * i)) & 0xff);
}

// pose_cov_t: 8 fingerprint + 3 int64, then the length of `device`.
constexpr std::size_t kPoseDeviceLength = 8 + 24;

}  // namespace

TEST(WireLayout, FingerprintsAreLcmGensForEveryType) {
  // A .lcm change moves lcm-gen's fingerprint: protocol/src/wire_layout.cpp must follow.
  EXPECT_EQ(wire::layout_of<pose_cov_t>().fingerprint, static_cast<std::uint64_t>(pose_cov_t::getHash()));
  EXPECT_EQ(wire::layout_of<truth_pose_t>().fingerprint, static_cast<std::uint64_t>(truth_pose_t::getHash()));
  EXPECT_EQ(wire::layout_of<device_status_t>().fingerprint,
            static_cast<std::uint64_t>(device_status_t::getHash()));
  EXPECT_EQ(wire::layout_of<device_claim_t>().fingerprint,
            static_cast<std::uint64_t>(device_claim_t::getHash()));
  EXPECT_EQ(wire::layout_of<raw_bytes_t>().fingerprint, static_cast<std::uint64_t>(raw_bytes_t::getHash()));
  EXPECT_EQ(wire::layout_of<image_t>().fingerprint, static_cast<std::uint64_t>(image_t::getHash()));
}

TEST(WireDecode, ValidMessagesOfEveryTypeDecodeToWhatWasEncoded) {
  auto p = decode_message<pose_cov_t>(encode(pose()));
  ASSERT_TRUE(p) << p.error().describe();
  EXPECT_EQ(p->sequence, 42);
  EXPECT_EQ(p->sensor, "head");
  EXPECT_EQ(encode(*p), encode(pose()));

  truth_pose_t t{};
  t.device = "d";
  t.sensor = "s";
  t.parent_frame = "";  // the shortest string: just its NUL
  t.child_frame = "c";
  ASSERT_TRUE(decode_message<truth_pose_t>(encode(t)));

  auto s = decode_message<device_status_t>(encode(status()));
  ASSERT_TRUE(s) << s.error().describe();
  EXPECT_EQ(s->detail, "no tag in view");

  for (std::size_t n : {0u, 1u, 5000u}) {
    auto r = decode_message<raw_bytes_t>(encode(raw(n)));
    ASSERT_TRUE(r) << n << ": " << r.error().describe();
    EXPECT_EQ(r->data.size(), n);
  }
  auto i = decode_message<image_t>(encode(image()));
  ASSERT_TRUE(i) << i.error().describe();
  EXPECT_EQ(i->data, (std::vector<std::uint8_t>{1, 2, 3}));
}

TEST(WireDecode, StringLengthOfZeroOrLessIsRejectedNotThrown) {
  // LCM's decoder assigns length - 1 characters: these ended `covtrack echo` with std::length_error.
  for (std::int32_t length : {0, -1, -7, INT_MIN}) {
    auto bytes = encode(pose());
    put_int32(bytes, kPoseDeviceLength, length);
    const auto d = decode_message<pose_cov_t>(bytes);
    ASSERT_FALSE(d) << length;
    EXPECT_EQ(d.error().fault, WireFault::BadLength);
    EXPECT_NE(d.error().detail.find("'device' at byte 32"), std::string::npos) << d.error().detail;
  }
  for (std::int32_t length : {0, -1}) {  // the last string of a heartbeat too
    auto bytes = encode(status());
    const char* text = "no tag in view";  // detail's characters, after its 4-byte length
    const auto found = std::search(bytes.begin(), bytes.end(), reinterpret_cast<const std::byte*>(text),
                                   reinterpret_cast<const std::byte*>(text) + std::strlen(text));
    ASSERT_NE(found, bytes.end());
    const std::size_t detail_at = static_cast<std::size_t>(found - bytes.begin()) - 4;
    put_int32(bytes, detail_at, length);
    const auto d = decode_message<device_status_t>(bytes);
    ASSERT_FALSE(d);
    EXPECT_EQ(d.error().fault, WireFault::BadLength);
    EXPECT_NE(d.error().detail.find("'detail'"), std::string::npos) << d.error().detail;
  }
}

TEST(WireDecode, StringLengthPastTheEndOrDisagreeingWithItsNulIsRejected) {
  auto bytes = encode(pose());
  put_int32(bytes, kPoseDeviceLength, INT_MAX);
  EXPECT_EQ(decode_message<pose_cov_t>(bytes).error().fault, WireFault::BadLength);
  // "dev\0" is 4 bytes: 3 cuts the NUL, 2 puts a NUL-less tail into the next field.
  for (std::int32_t length : {2, 3, 5}) {
    bytes = encode(pose());
    put_int32(bytes, kPoseDeviceLength, length);
    const auto d = decode_message<pose_cov_t>(bytes);
    ASSERT_FALSE(d) << length;
    EXPECT_EQ(d.error().fault, WireFault::BadLength) << d.error().describe();
  }
}

TEST(WireDecode, ArrayLengthsAreCheckedBeforeAnythingIsAllocated) {
  const auto base = encode(raw(16));
  const std::size_t length_at = base.size() - 16 - 4;
  for (std::int32_t length : {INT_MAX, 17, -1, INT_MIN}) {
    auto bytes = base;
    put_int32(bytes, length_at, length);
    const auto d = decode_message<raw_bytes_t>(bytes);
    ASSERT_FALSE(d) << length;
    EXPECT_EQ(d.error().fault, WireFault::BadLength) << d.error().describe();
    EXPECT_NE(d.error().detail.find("array 'data'"), std::string::npos) << d.error().detail;
  }
  auto bytes = base;
  put_int32(bytes, length_at, 15);  // one byte too many for the array: it is left over
  EXPECT_EQ(decode_message<raw_bytes_t>(bytes).error().fault, WireFault::TrailingBytes);
}

TEST(WireDecode, WrongTypeTruncationAndTrailingBytesAreRejected) {
  const auto truth_bytes = encode(truth_pose_t{});
  const auto as_pose = decode_message<pose_cov_t>(truth_bytes);
  ASSERT_FALSE(as_pose);
  EXPECT_EQ(as_pose.error().fault, WireFault::WrongType);
  EXPECT_NE(as_pose.error().detail.find("pose_cov_t"), std::string::npos);

  const auto full = encode(pose());
  for (std::size_t n = 0; n < full.size(); ++n) {
    const auto d = decode_message<pose_cov_t>(std::span(full).first(n));
    ASSERT_FALSE(d) << n;
    EXPECT_TRUE(d.error().fault == WireFault::Truncated || d.error().fault == WireFault::BadLength)
        << n << ": " << d.error().describe();
  }
  auto longer = full;
  longer.push_back(std::byte{0});
  EXPECT_EQ(decode_message<pose_cov_t>(longer).error().fault, WireFault::TrailingBytes);
}

TEST(WireDecode, RandomMutationsAreRejectedOrDecodeToWhatReEncodesToTheSameBytes) {
  std::mt19937 rng(21);
  const std::vector<std::vector<std::byte>> seeds = {encode(pose()), encode(status()), encode(raw(40))};
  int accepted = 0, rejected = 0;
  for (int i = 0; i < 30000; ++i) {
    auto bytes = seeds[i % seeds.size()];
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int f = 0; f < flips; ++f) bytes[rng() % bytes.size()] ^= std::byte(1u << (rng() % 8));
    if (rng() % 8 == 0) bytes.resize(rng() % bytes.size());
    const auto check = [&](auto decoded) {
      if (!decoded) return ++rejected, void();
      ++accepted;
      EXPECT_EQ(encode(*decoded), bytes) << "message " << i;  // nothing was read that is not there
    };
    switch (i % seeds.size()) {
      case 0: check(decode_message<pose_cov_t>(bytes)); break;
      case 1: check(decode_message<device_status_t>(bytes)); break;
      default: check(decode_message<raw_bytes_t>(bytes)); break;
    }
  }
  // Most flips land in numbers (still a message), many in lengths and fingerprints.
  EXPECT_GT(accepted, 1000);
  EXPECT_GT(rejected, 1000);
}

TEST(WireDecode, NamesMustFollowTheNamingRulesAndTextMustBeUtf8) {
  for (const std::string& device : {std::string(""), std::string("a b"), std::string(24, 'd'),
                                     std::string("caf\xc3\xa9"), std::string("x\xff")}) {
    const auto d = decode_message<pose_cov_t>(encode(pose(device)));
    ASSERT_FALSE(d) << printable(device);
    EXPECT_EQ(d.error().fault, WireFault::BadName) << d.error().describe();
    EXPECT_EQ(invalid_utf8_at(d.error().detail), std::nullopt) << "the detail is printable";
  }
  for (const std::string& frame : {std::string("w\xff"), std::string("\xc0\xaf"), std::string("w\x1b[2J"),
                                   std::string("w\xc2\x9b")}) {
    auto m = pose();
    m.parent_frame = frame;
    const auto d = decode_message<pose_cov_t>(encode(m));
    ASSERT_FALSE(d) << printable(frame);
    EXPECT_EQ(d.error().fault, WireFault::BadText);
    EXPECT_NE(d.error().detail.find("'parent_frame'"), std::string::npos) << d.error().detail;
    EXPECT_FALSE(control_character_at(d.error().detail)) << d.error().detail;
  }
  auto m = pose();
  m.child_frame = "Kopf \xc3\xa9";  // any UTF-8 without control characters is a frame
  EXPECT_TRUE(decode_message<pose_cov_t>(encode(m)));

  auto s = status();
  s.last_error = "line 1\nline 2\ttab";  // free text may hold control characters...
  EXPECT_TRUE(decode_message<device_status_t>(encode(s)));
  s.last_error = "bad \xe2\x82";  // ...but must be UTF-8
  EXPECT_EQ(decode_message<device_status_t>(encode(s)).error().fault, WireFault::BadText);
  s = status();
  s.driver = "sim\n";
  EXPECT_EQ(decode_message<device_status_t>(encode(s)).error().fault, WireFault::BadText);
}

TEST(ChannelMessages, NamesMustBeTheChannels) {
  const auto bytes = encode(pose("dev", "head"));
  EXPECT_TRUE(decode_pose("covtrack/pose/dev/head", bytes));
  const auto other = decode_pose("covtrack/pose/dev/hand", bytes);
  ASSERT_FALSE(other);
  EXPECT_EQ(other.error().fault, WireFault::WrongChannel);
  EXPECT_NE(other.error().detail.find("'dev/head'"), std::string::npos);
  for (const char* channel : {"covtrack/pose/dev", "covtrack/pose/dev/he ad", "covtrack/pose//head",
                              "covtrack/pose/dev/head/x"}) {
    const auto d = decode_pose(channel, bytes);
    ASSERT_FALSE(d) << channel;
    EXPECT_EQ(d.error().fault, WireFault::BadChannel) << channel;
  }
  EXPECT_TRUE(decode_status("covtrack/status/dev", encode(status("dev"))));
  EXPECT_EQ(decode_status("covtrack/status/other", encode(status("dev"))).error().fault, WireFault::WrongChannel);
}

TEST(ChannelMessages, HeartbeatValuesMustBeInRange) {
  const auto bad = [](auto change) {
    auto s = status();
    change(s);
    const auto d = decode_status("covtrack/status/dev", encode(s));
    return d ? std::string("accepted") : d.error().describe();
  };
  EXPECT_EQ(bad([](device_status_t&) {}), "accepted");
  EXPECT_EQ(bad([](device_status_t& s) { s.state = 9; }), "bad value: unknown state 9");
  EXPECT_EQ(bad([](device_status_t& s) { s.rate_hz = NAN; }), "bad value: rate_hz nan is not a rate");
  EXPECT_EQ(bad([](device_status_t& s) { s.rate_hz = -1; }), "bad value: rate_hz -1 is not a rate");
  EXPECT_EQ(bad([](device_status_t& s) { s.heartbeat_period_us = 0; }),
            "bad value: heartbeat_period_us 0 is outside 1000-3600000000");
  EXPECT_EQ(bad([](device_status_t& s) { s.host = "pc\x1b"; }).substr(0, 8), "bad text");
}

TEST(ChannelMessages, ClaimsDecodeOnTheirDevicesChannelWithAKnownStage) {
  device_claim_t c{};
  c.time_us = 1;
  c.device = "dev";
  c.instance_id = -5;
  c.host = "pc";
  c.pid = 42;
  c.claimed_us = 7;
  c.stage = device_claim_t::STAGE_HOLDING;
  const auto d = decode_claim(claim_channel("dev"), encode(c));
  ASSERT_TRUE(d) << d.error().describe();
  EXPECT_EQ(encode(*d), encode(c));
  EXPECT_EQ(decode_claim(claim_channel("other"), encode(c)).error().fault, WireFault::WrongChannel);
  EXPECT_EQ(decode_claim(claim_channel("dev"), encode(status())).error().fault, WireFault::WrongType);
  c.stage = 2;
  EXPECT_EQ(decode_claim(claim_channel("dev"), encode(c)).error().describe(), "bad value: unknown stage 2");
  EXPECT_EQ(check_channel_message(claim_channel("dev"), encode(c))->fault, WireFault::BadValue);
}

TEST(ChannelMessages, CheckOfAnyChannelKnowsEachKindAndLeavesOthersAlone) {
  EXPECT_FALSE(check_channel_message(pose_channel("dev", "head"), encode(pose())));
  EXPECT_FALSE(check_channel_message(status_channel("dev"), encode(status())));
  EXPECT_FALSE(check_channel_message(raw_channel("dev"), encode(raw(3))));
  EXPECT_FALSE(check_channel_message(image_channel("cam"), encode(image())));
  truth_pose_t t{};
  t.device = "dev";
  t.sensor = "head";
  EXPECT_FALSE(check_channel_message(truth_channel("dev", "head"), encode(t)));
  // Each kind is decoded as its own type: a pose is no heartbeat, nor a truth.
  EXPECT_EQ(check_channel_message(status_channel("dev"), encode(pose()))->fault, WireFault::WrongType);
  EXPECT_EQ(check_channel_message(truth_channel("dev", "head"), encode(pose()))->fault, WireFault::WrongType);
  EXPECT_FALSE(check_channel_message("OTHER_APP", std::vector<std::byte>(3)));  // not covtrack's
}
