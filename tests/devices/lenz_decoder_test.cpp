// The XpressNet decoder on byte vectors: framing, XOR, LI-USB prefixes, resync on
// garbage, and every message of docs/xpressnet.md (values from there).
#include <gtest/gtest.h>

#include <variant>
#include <vector>

#include "feedback_state.hpp"
#include "xpressnet_framing.hpp"
#include "xpressnet_messages.hpp"

using namespace covtrack::lenz;
using Bytes = std::vector<std::uint8_t>;

namespace {

std::vector<Frame> decode(const Bytes& bytes, FrameDecoder* decoder = nullptr) {
  FrameDecoder local;
  return (decoder ? *decoder : local).push(bytes);
}

template <class T>
T reply_as(const Bytes& bytes) {
  const auto frames = decode(bytes);
  EXPECT_EQ(frames.size(), 1u);
  if (frames.empty()) return T{};
  const Reply r = interpret_reply(frames[0]);
  EXPECT_TRUE(std::holds_alternative<T>(r)) << "variant index " << r.index();
  return std::holds_alternative<T>(r) ? std::get<T>(r) : T{};
}

template <class T>
T request_as(const Bytes& bytes) {
  const auto frames = decode(bytes);
  EXPECT_EQ(frames.size(), 1u);
  if (frames.empty()) return T{};
  const Request r = interpret_request(frames[0]);
  EXPECT_TRUE(std::holds_alternative<T>(r)) << "variant index " << r.index();
  return std::holds_alternative<T>(r) ? std::get<T>(r) : T{};
}

}  // namespace

TEST(XpressNetFraming, EncodesTheReferenceExamples) {
  EXPECT_EQ(encode_frame(Bytes{0x21, 0x24}), (Bytes{0x21, 0x24, 0x05}));
  EXPECT_EQ(encode_frame(Bytes{0x21, 0x21}), (Bytes{0x21, 0x21, 0x00}));
  EXPECT_EQ(encode_frame(Bytes{0xF0}), (Bytes{0xF0, 0xF0}));
  EXPECT_EQ(encode_frame(Bytes{0x02, 0x01, 0x36}), (Bytes{0x02, 0x01, 0x36, 0x35}));  // not JMRI's 34
  EXPECT_EQ(encode_frame(Bytes{0x63, 0x21, 0x36, 0x00}), (Bytes{0x63, 0x21, 0x36, 0x00, 0x74}));
  EXPECT_EQ(encode_frame(Bytes{0x21, 0x21}, Prefix::Reply), (Bytes{0xFF, 0xFE, 0x21, 0x21, 0x00}));
  EXPECT_EQ(encode_frame(Bytes{0x61, 0x01}, Prefix::Unsolicited), (Bytes{0xFF, 0xFD, 0x61, 0x01, 0x60}));
}

TEST(XpressNetFraming, SplitsAStreamAndWaitsForPartialFrames) {
  FrameDecoder d;
  EXPECT_TRUE(d.push(Bytes{0x62, 0x22}).empty());  // incomplete
  auto frames = d.push(Bytes{0x00, 0x40, 0x01, 0x04, 0x05, 0x61});
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].bytes, (Bytes{0x62, 0x22, 0x00}));
  EXPECT_EQ(frames[1].bytes, (Bytes{0x01, 0x04}));
  frames = d.push(Bytes{0x01, 0x60});
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].bytes, (Bytes{0x61, 0x01}));
  EXPECT_EQ(d.counters().frames, 3u);
  EXPECT_EQ(d.counters().bad_frames, 0u);
}

TEST(XpressNetFraming, BadXorIsCountedSkippedAndNeverTrusted) {
  FrameDecoder d;
  // A feedback frame with its XOR byte corrupted, then a good status reply.
  const auto frames = d.push(Bytes{0x42, 0x40, 0x41, 0x00, 0x62, 0x22, 0x00, 0x40});
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].bytes, (Bytes{0x62, 0x22, 0x00}));
  EXPECT_GE(d.counters().bad_frames, 1u);
}

TEST(XpressNetFraming, ResynchronisesAfterGarbageBetweenFrames) {
  FrameDecoder d;
  Bytes stream{0x61, 0x01, 0x60};  // good
  for (std::uint8_t g : {0x13, 0x37, 0x00, 0x99, 0x42}) stream.push_back(g);  // garbage
  for (std::uint8_t b : {0x42, 0x40, 0x41, 0x43}) stream.push_back(b);       // good feedback
  for (std::uint8_t b : {0x62, 0x22, 0x00, 0x40}) stream.push_back(b);       // good status
  std::vector<Frame> frames = d.push(stream);
  // Feed more traffic so that any garbage header still waiting for its length resolves.
  for (int i = 0; i < 5; ++i) {
    auto more = d.push(Bytes{0x62, 0x22, 0x00, 0x40});
    frames.insert(frames.end(), more.begin(), more.end());
  }
  int feedback = 0, status = 0, power_on = 0;
  for (const auto& f : frames) {
    const Reply r = interpret_reply(f);
    if (std::holds_alternative<Feedback>(r)) ++feedback;
    if (std::holds_alternative<CommandStationStatus>(r)) ++status;
    if (std::holds_alternative<Broadcast>(r)) ++power_on;
  }
  EXPECT_EQ(power_on, 1);
  EXPECT_EQ(feedback, 1);
  EXPECT_EQ(status, 6);
  EXPECT_GT(d.counters().skipped_bytes, 0u);
}

// A stray byte read as a header asks for up to 17 more; the frames that follow must not
// wait behind it for bytes of later frames (at keep-alive pace that was 0.15-2 s).
TEST(XpressNetFraming, AStrayHeaderDoesNotHoldBackTheFramesAfterIt) {
  FrameDecoder d;
  ASSERT_EQ(d.push(Bytes{0x61, 0x01, 0x60}).size(), 1u);  // in step
  EXPECT_TRUE(d.push(Bytes{0x4F}).empty());                 // noise: a header of 15 data bytes?
  auto frames = d.push(Bytes{0x62, 0x22, 0x00, 0x40});     // the next status reply
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].bytes, (Bytes{0x62, 0x22, 0x00}));
  // After garbage, out of step: a whole frame anywhere in the input is taken at once,
  // and the prefix before it is kept.
  frames = d.push(Bytes{0x13, 0x37, 0x9F, 0xFF, 0xFD, 0x42, 0x40, 0x41, 0x43, 0x62});
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].bytes, (Bytes{0x42, 0x40, 0x41}));
  EXPECT_EQ(frames[0].prefix, Prefix::Unsolicited);
  frames = d.push(Bytes{0x22, 0x00, 0x40});
  ASSERT_EQ(frames.size(), 1u);  // and the partial one that followed completes normally
  EXPECT_EQ(frames[0].bytes, (Bytes{0x62, 0x22, 0x00}));
  // A frame arriving in pieces is still waited for.
  EXPECT_TRUE(d.push(Bytes{0x42, 0x40}).empty());
  frames = d.push(Bytes{0x41, 0x43});
  ASSERT_EQ(frames.size(), 1u);
  // Each run of garbage is one bad frame, not one per byte.
  EXPECT_EQ(d.counters().bad_frames, 2u);
}

TEST(XpressNetFraming, LiUsbPrefixesTellRepliesFromBroadcasts) {
  FrameDecoder d;
  const auto frames = d.push(Bytes{0xFF, 0xFE, 0x62, 0x22, 0x00, 0x40, 0xFF, 0xFD, 0x42, 0x40, 0x41, 0x43,
                                   0x61, 0x00, 0x61});
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].prefix, Prefix::Reply);
  EXPECT_EQ(frames[1].prefix, Prefix::Unsolicited);
  EXPECT_EQ(frames[2].prefix, Prefix::None);  // LI101F style: no prefix
  EXPECT_EQ(d.counters().bad_frames, 0u);
}

TEST(XpressNetFraming, F0AndF2AreHeadersNotPrefixes) {
  const auto frames = decode(Bytes{0xFF, 0xFE, 0xF0, 0xF0, 0xF2, 0x01, 0x01, 0xF2});
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].bytes, (Bytes{0xF0}));
  EXPECT_EQ(frames[1].bytes, (Bytes{0xF2, 0x01, 0x01}));
}

TEST(XpressNetMessages, InterfaceNotices) {
  const std::vector<std::pair<Bytes, std::uint8_t>> cases = {
      {{0x01, 0x01, 0x00}, 1}, {{0x01, 0x02, 0x03}, 2}, {{0x01, 0x03, 0x02}, 3}, {{0x01, 0x04, 0x05}, 4},
      {{0x01, 0x05, 0x04}, 5}, {{0x01, 0x06, 0x07}, 6}, {{0x01, 0x07, 0x06}, 7}, {{0x01, 0x08, 0x09}, 8},
      {{0x01, 0x09, 0x08}, 9}, {{0x01, 0x0A, 0x0B}, 10}};
  for (const auto& [bytes, code] : cases) {
    EXPECT_EQ(reply_as<InterfaceNotice>(bytes).code, code);
    EXPECT_FALSE(describe_notice(code).empty());
  }
  EXPECT_NE(describe_notice(6).find("overflow"), std::string::npos);
}

TEST(XpressNetMessages, VersionsAndStatus) {
  const auto li = reply_as<InterfaceVersion>({0x02, 0x01, 0x36, 0x35});
  EXPECT_EQ(li.hardware_bcd, 0x01);
  EXPECT_EQ(li.software_bcd, 0x36);
  const auto cs3 = reply_as<CommandStationVersion>({0x63, 0x21, 0x36, 0x00, 0x74});
  EXPECT_EQ(cs3.version_bcd, 0x36);
  EXPECT_EQ(cs3.type, 0);
  const auto cs2 = reply_as<CommandStationVersion>({0x62, 0x21, 0x21, 0x62});
  EXPECT_EQ(cs2.version_bcd, 0x21);
  EXPECT_EQ(cs2.type, -1);
  EXPECT_EQ(reply_as<CommandStationStatus>({0x62, 0x22, 0x00, 0x40}).bits, 0x00);
  EXPECT_EQ(reply_as<CommandStationStatus>({0x62, 0x22, 0xFF, 0xBF}).bits, 0xFF);
  const auto addr = reply_as<InterfaceSetting>({0xF2, 0x01, 0x01, 0xF2});
  EXPECT_EQ(addr.which, 1);
  EXPECT_EQ(addr.value, 1);
  EXPECT_EQ(reply_as<InterfaceSetting>({0xF2, 0x02, 0x04, 0xF4}).value, 4);
}

TEST(XpressNetMessages, Broadcasts) {
  const std::vector<std::pair<Bytes, BroadcastKind>> cases = {
      {{0x61, 0x00, 0x61}, BroadcastKind::TrackPowerOff},   {{0x61, 0x01, 0x60}, BroadcastKind::TrackPowerOn},
      {{0x61, 0x02, 0x63}, BroadcastKind::ServiceMode},     {{0x61, 0x80, 0xE1}, BroadcastKind::TransferError},
      {{0x61, 0x81, 0xE0}, BroadcastKind::CommandStationBusy}, {{0x61, 0x82, 0xE3}, BroadcastKind::NotSupported},
      {{0x81, 0x00, 0x81}, BroadcastKind::EmergencyStop}};
  for (const auto& [bytes, kind] : cases) EXPECT_EQ(reply_as<Broadcast>(bytes).kind, kind);
  EXPECT_TRUE(std::holds_alternative<UnknownReply>(interpret_reply(decode({0x61, 0x55, 0x34}).at(0))));
}

TEST(XpressNetMessages, FeedbackWithSeveralPairs) {
  // Module 65 (wire 64) inputs 1-4: input 2 occupied; module 66 (wire 65) inputs 5-8:
  // input 8 occupied; a turnout pair (type 1) for group 3.
  const Bytes body{0x46, 0x40, 0x42, 0x41, 0x58, 0x03, 0x21};
  const auto fb = reply_as<Feedback>(encode_frame(body));
  ASSERT_EQ(fb.pairs.size(), 3u);
  EXPECT_EQ(fb.pairs[0].address, 0x40);
  EXPECT_TRUE(fb.pairs[0].is_feedback_module());
  EXPECT_FALSE(fb.pairs[0].upper_nibble());
  EXPECT_EQ(fb.pairs[0].inputs(), 0x02);
  EXPECT_TRUE(fb.pairs[1].upper_nibble());
  EXPECT_EQ(fb.pairs[1].inputs(), 0x08);
  EXPECT_FALSE(fb.pairs[2].is_feedback_module());
  EXPECT_EQ(fb.pairs[2].type(), 1);

  FeedbackState state;
  EXPECT_FALSE(state.input(65, 2).has_value());  // unknown until reported
  EXPECT_TRUE(state.apply(fb));
  EXPECT_EQ(state.input(65, 2), true);
  EXPECT_EQ(state.input(65, 1), false);
  EXPECT_FALSE(state.input(65, 5).has_value());  // the other nibble is still unknown
  EXPECT_EQ(state.input(66, 8), true);           // JMRI XS66:8 = sensor 528
  EXPECT_EQ(state.input(66, 5), false);
  EXPECT_FALSE(state.input(66, 1).has_value());
  EXPECT_FALSE(state.apply(fb));  // nothing new
  // Clearing module 65's lower nibble leaves its upper nibble alone.
  EXPECT_TRUE(state.apply(Feedback{{{0x40, 0x40}}}));
  EXPECT_EQ(state.input(65, 2), false);
  EXPECT_EQ(state.input(66, 8), true);
}

TEST(XpressNetMessages, RequestsRoundTrip) {
  EXPECT_TRUE((std::holds_alternative<InterfaceVersionRequest>(interpret_request(decode({0xF0, 0xF0}).at(0)))));
  request_as<CommandStationVersionRequest>({0x21, 0x21, 0x00});
  request_as<CommandStationStatusRequest>({0x21, 0x24, 0x05});
  EXPECT_TRUE(request_as<TrackPowerRequest>({0x21, 0x81, 0xA0}).on);
  EXPECT_FALSE(request_as<TrackPowerRequest>({0x21, 0x80, 0xA1}).on);
  request_as<EmergencyStopRequest>({0x80, 0x80});
  const auto fr = request_as<FeedbackRequest>(encode_frame(Bytes{0x42, 98, 0x80}));  // module 99
  EXPECT_EQ(fr.address, 98);
  EXPECT_FALSE(fr.upper_nibble);
  EXPECT_TRUE(request_as<FeedbackRequest>(encode_frame(Bytes{0x42, 98, 0x81})).upper_nibble);
  EXPECT_EQ(request_as<InterfaceSettingRequest>({0xF2, 0x02, 0x01, 0xF1}).value, 1);
  // Builders produce exactly these bytes.
  EXPECT_EQ(encode_frame(request_bytes(CommandStationStatusRequest{})), (Bytes{0x21, 0x24, 0x05}));
  EXPECT_EQ(encode_frame(request_bytes(InterfaceVersionRequest{})), (Bytes{0xF0, 0xF0}));
  EXPECT_EQ(encode_frame(request_bytes(TrackPowerRequest{true})), (Bytes{0x21, 0x81, 0xA0}));
  EXPECT_EQ(encode_frame(request_bytes(EmergencyStopRequest{})), (Bytes{0x80, 0x80}));
  EXPECT_EQ(encode_frame(reply_bytes(CommandStationVersion{0x36, 0x00})), (Bytes{0x63, 0x21, 0x36, 0x00, 0x74}));
  EXPECT_EQ(encode_frame(reply_bytes(Broadcast{BroadcastKind::EmergencyStop})), (Bytes{0x81, 0x00, 0x81}));
  EXPECT_TRUE(std::holds_alternative<UnknownRequest>(interpret_request(decode({0x22, 0x11, 0x33, 0x00}).at(0))));
}
