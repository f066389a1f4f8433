// The serial 6-DOF decoders: every protocol, optional fields, both units, status letters,
// and resync after garbage or a cut record.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "record_encoder.hpp"
#include "serial6dof_stream.hpp"

using namespace covtrack;
using namespace covtrack::serial6dof;

namespace {

TrackerRecord sample_record(int station, char status = ' ') {
  TrackerRecord r;
  r.station = station;
  r.position_m = Vec3(0.12, -0.34, 0.56);
  r.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  r.status_code = status;
  return r;
}

template <typename Decoder>
std::vector<TrackerRecord> records_of(Decoder& d, const Bytes& bytes) {
  std::vector<TrackerRecord> out;
  for (auto& item : d.feed(bytes))
    if (auto* r = std::get_if<TrackerRecord>(&item)) out.push_back(*r);
  return out;
}

void expect_pose_near(const TrackerRecord& got, const TrackerRecord& want, double tol_m,
                      double tol_q) {
  EXPECT_EQ(got.station, want.station);
  EXPECT_LT((got.position_m - want.position_m).norm(), tol_m);
  EXPECT_LT((got.orientation.coeffs() - want.orientation.coeffs()).norm(), tol_q);
}

Bytes operator+(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace

// A record written out by hand from the manual's layout, not by our encoder.
TEST(FastrakDecoder, HandBuiltRecordInInches) {
  Bytes b = {'0', '2', ' '};
  auto put = [&](float f) {
    std::uint8_t x[4];
    std::memcpy(x, &f, 4);  // this test runs on little-endian machines, like the device
    b.insert(b.end(), x, x + 4);
  };
  for (float f : {10.0f, -5.0f, 2.5f, 1.0f, 0.0f, 0.0f, 0.0f}) put(f);
  b.insert(b.end(), {'\r', '\n'});
  ASSERT_EQ(b.size(), 33u);
  FastrakDecoder d({Units::Inches, {}, true});
  auto recs = records_of(d, b);
  ASSERT_EQ(recs.size(), 1u);
  EXPECT_EQ(recs[0].station, 2);
  EXPECT_FALSE(recs[0].trouble);
  EXPECT_NEAR(recs[0].position_m.x(), 0.254, 1e-7);
  EXPECT_NEAR(recs[0].position_m.y(), -0.127, 1e-7);
  EXPECT_NEAR(recs[0].orientation.w(), 1.0, 1e-7);
}

TEST(FastrakDecoder, BothUnitsAndEveryOptionalItem) {
  for (Units units : {Units::Inches, Units::Centimetres}) {
    for (const auto& extras : std::vector<std::vector<FastrakExtra>>{
             {}, {FastrakExtra::Timestamp}, {FastrakExtra::Timestamp, FastrakExtra::Buttons},
             {FastrakExtra::Stylus}, {FastrakExtra::Timestamp, FastrakExtra::Buttons, FastrakExtra::Joystick}}) {
      for (bool crlf : {true, false}) {
        const FastrakFormat f{units, extras, crlf};
        TrackerRecord r = sample_record(3);
        r.device_time_s = 12.5;
        r.buttons = 1;
        const Bytes b = encode_fastrak_record(r, f);
        ASSERT_EQ(b.size(), fastrak_record_size(f));
        FastrakDecoder d(f);
        auto recs = records_of(d, b);
        ASSERT_EQ(recs.size(), 1u);
        expect_pose_near(recs[0], r, 1e-6, 1e-6);
        const bool has_time = std::find(extras.begin(), extras.end(), FastrakExtra::Timestamp) != extras.end();
        EXPECT_EQ(recs[0].device_time_s.has_value(), has_time);
        if (has_time) {
          EXPECT_NEAR(*recs[0].device_time_s, 12.5, 1e-6);
        }
        if (!extras.empty() && extras.back() != FastrakExtra::Timestamp) {
          EXPECT_EQ(recs[0].buttons.value_or(9), 1u);
        }
        EXPECT_EQ(d.resyncs(), 0u);
      }
    }
  }
  // The same bytes read with the wrong units are 2.54 times off: units matter.
  const Bytes b = encode_fastrak_record(sample_record(1), {Units::Inches, {}, true});
  FastrakDecoder wrong({Units::Centimetres, {}, true});
  auto recs = records_of(wrong, b);
  ASSERT_EQ(recs.size(), 1u);
  EXPECT_NEAR(recs[0].position_m.x(), 0.12 / 2.54, 1e-6);
}

TEST(FastrakDecoder, StatusLettersFlagTrouble) {
  const FastrakFormat f{Units::Centimetres, {}, true};
  FastrakDecoder d(f);
  auto recs = records_of(d, encode_fastrak_record(sample_record(1, 'B'), f) +
                                encode_fastrak_record(sample_record(1, ' '), f));
  ASSERT_EQ(recs.size(), 2u);
  EXPECT_TRUE(recs[0].trouble);
  EXPECT_EQ(recs[0].status_code, 'B');
  EXPECT_FALSE(recs[1].trouble);
}

TEST(FastrakDecoder, ResyncAfterGarbageAndCutRecord) {
  const FastrakFormat f{Units::Centimetres, {FastrakExtra::Timestamp}, true};
  const Bytes good = encode_fastrak_record(sample_record(1), f);
  const Bytes cut(good.begin(), good.begin() + 17);
  const Bytes garbage = {'x', '0', 0xFF, '2', '9', 0x00, '0', '1', ' ', 7};
  FastrakDecoder d(f);
  // Fed one byte at a time: framing must not depend on read boundaries.
  const Bytes all = garbage + good + cut + good + good;
  std::vector<TrackerRecord> recs;
  for (auto byte : all) {
    auto got = records_of(d, Bytes{byte});
    recs.insert(recs.end(), got.begin(), got.end());
  }
  ASSERT_EQ(recs.size(), 3u);
  for (const auto& r : recs) expect_pose_near(r, sample_record(1), 1e-6, 1e-6);
  EXPECT_GE(d.resyncs(), 2u);
}

TEST(FastrakDecoder, StatusRecordReportsUnits) {
  for (Units units : {Units::Inches, Units::Centimetres}) {
    const Bytes s = encode_fastrak_status(1, units);
    EXPECT_EQ(s.size(), 55u);
    FastrakDecoder d({units, {}, true});
    auto items = d.feed(s);
    ASSERT_EQ(items.size(), 1u);
    auto* reply = std::get_if<DeviceReply>(&items[0]);
    ASSERT_NE(reply, nullptr);
    EXPECT_EQ(reply->command, 'S');
    EXPECT_EQ(fastrak_status_units(*reply), units);
  }
  EXPECT_EQ(fastrak_status_units(DeviceReply{'S', 1, 0, "21SZZZ"}), std::nullopt);
}

TEST(FastrakDecoder, RejectsNonFiniteAndNonUnitQuaternion) {
  const FastrakFormat f{Units::Centimetres, {}, true};
  TrackerRecord nan_rec = sample_record(1);
  nan_rec.position_m.x() = std::nan("");
  TrackerRecord long_q = sample_record(1);
  long_q.orientation.coeffs() *= 2;
  FastrakDecoder d(f);
  auto recs = records_of(d, encode_fastrak_record(nan_rec, f) + encode_fastrak_record(long_q, f) +
                                encode_fastrak_record(sample_record(2), f));
  ASSERT_EQ(recs.size(), 1u);
  EXPECT_EQ(recs[0].station, 2);
  EXPECT_GE(d.bad_records(), 2u);
  EXPECT_FALSE(d.last_problem().empty());
}

// Found by fuzz_fastrak: the timestamp item is a float, and a NaN there passed.
TEST(FastrakDecoder, RejectsNonFiniteTimestamp) {
  const FastrakFormat f{Units::Centimetres, {FastrakExtra::Timestamp}, true};
  TrackerRecord nan_time = sample_record(1);
  nan_time.device_time_s = std::nan("");
  FastrakDecoder d(f);
  auto recs = records_of(d, encode_fastrak_record(nan_time, f) + encode_fastrak_record(sample_record(2), f));
  ASSERT_EQ(recs.size(), 1u);
  EXPECT_EQ(recs[0].station, 2);
  EXPECT_EQ(d.bad_records(), 1u);
  EXPECT_NE(d.last_problem().find("non-finite"), std::string::npos);
}

TEST(FastrakDecoder, OutputListCommand) {
  EXPECT_EQ(fastrak_output_list_command(2, {Units::Inches, {FastrakExtra::Timestamp}, true}),
            "O2,2,11,21,1\r");
  EXPECT_EQ(fastrak_output_list_command(1, {Units::Inches, {}, false}), "O1,2,11,0\r");
}

TEST(LibertyDecoder, HandBuiltHeaderAndBothUnits) {
  for (Units units : {Units::Inches, Units::Centimetres}) {
    const LibertyFormat f{units, {LibertyExtra::Timestamp}};
    TrackerRecord r = sample_record(4);
    r.status_code = 0;
    r.device_time_s = 3.25;
    const Bytes b = encode_liberty_record(r, f);
    ASSERT_EQ(b.size(), 8u + 12 + 16 + 4 + 2);
    EXPECT_EQ(b[0], 'L');
    EXPECT_EQ(b[1], 'Y');
    EXPECT_EQ(b[2], 4);    // binary station number
    EXPECT_EQ(b[6], 34);   // payload size, little-endian
    EXPECT_EQ(b[7], 0);
    LibertyDecoder d(f);
    auto recs = records_of(d, b);
    ASSERT_EQ(recs.size(), 1u);
    expect_pose_near(recs[0], r, 1e-6, 1e-6);
    EXPECT_NEAR(recs[0].device_time_s.value_or(-1), 3.25, 1e-9);
    EXPECT_FALSE(recs[0].trouble);
  }
}

TEST(LibertyDecoder, OptionalItemsErrorCodesAndPreambles) {
  const LibertyFormat f{Units::Centimetres,
                        {LibertyExtra::Timestamp, LibertyExtra::FrameCount, LibertyExtra::Stylus}};
  TrackerRecord ok = sample_record(1);
  ok.status_code = 0x20;  // ASCII "no error" is OK too
  ok.buttons = 1;
  TrackerRecord bad = sample_record(2);
  bad.status_code = 0x05;
  LibertyDecoder d(f);
  auto recs = records_of(d, encode_liberty_record(ok, f, "PA") + encode_liberty_record(bad, f, "LU"));
  ASSERT_EQ(recs.size(), 2u);
  EXPECT_FALSE(recs[0].trouble);
  EXPECT_EQ(recs[0].buttons.value_or(0), 1u);
  EXPECT_TRUE(recs[1].trouble);
  EXPECT_EQ(recs[1].status_code, 5);
}

TEST(LibertyDecoder, RepliesAndResyncAfterGarbageAndCutFrame) {
  const LibertyFormat f{Units::Centimetres, {}};
  TrackerRecord r = sample_record(1);
  r.status_code = 0;
  const Bytes good = encode_liberty_record(r, f);
  const Bytes cut(good.begin(), good.begin() + 20);
  const std::string who = "Polhemus Liberty emulator";
  const Bytes reply = encode_liberty_frame(1, 0x16, 0, Bytes(who.begin(), who.end()));
  LibertyDecoder d(f);
  const Bytes all = Bytes{'L', 'x', 'L', 0, 1, 2} + good + cut + reply + good;
  std::vector<DecodedItem> items;
  for (auto byte : all) {
    auto got = d.feed(Bytes{byte});
    items.insert(items.end(), got.begin(), got.end());
  }
  ASSERT_EQ(items.size(), 3u);
  EXPECT_TRUE(std::holds_alternative<TrackerRecord>(items[0]));
  // The cut frame swallowed the reply's first bytes or the reply survived; either way
  // the last good record is found again.
  EXPECT_TRUE(std::holds_alternative<TrackerRecord>(items.back()));
  EXPECT_GE(d.resyncs(), 1u);
}

TEST(LibertyDecoder, ReplyFrameComesBackWhole) {
  const std::string who = "Polhemus Liberty emulator";
  LibertyDecoder d({Units::Centimetres, {}});
  auto items = d.feed(encode_liberty_frame(1, 0x16, 0, Bytes(who.begin(), who.end())));
  ASSERT_EQ(items.size(), 1u);
  auto* reply = std::get_if<DeviceReply>(&items[0]);
  ASSERT_NE(reply, nullptr);
  EXPECT_EQ(reply->command, 0x16);
  EXPECT_EQ(reply->payload, who);
}

TEST(FlockDecoder, HandBuiltWordsAndScaling) {
  // x = +half scale: 16384 counts = 0x4000 -> LS 0x80 | 0, MS 0x20; q0 = 0x7FFC -> LS 0xFF, MS 0x3F
  Bytes b = {0x80, 0x20, 0x00, 0x00, 0x00, 0x00, 0x7F, 0x3F, 0, 0, 0, 0, 0, 0};
  FlockDecoder d({36, false, 1});
  auto recs = records_of(d, b);
  ASSERT_EQ(recs.size(), 1u);
  EXPECT_NEAR(recs[0].position_m.x(), 18 * 0.0254, 1e-9);
  EXPECT_NEAR(recs[0].orientation.w(), 32764.0 / 32768.0, 1e-9);
  FlockDecoder wide({72, false, 1});
  EXPECT_NEAR(records_of(wide, b).at(0).position_m.x(), 36 * 0.0254, 1e-9);
}

TEST(FlockDecoder, GroupModeAddressAndNegativeValues) {
  const FlockFormat f{36, true, 1};
  TrackerRecord r = sample_record(3);
  r.position_m = Vec3(-0.4, 0.3, -0.2);
  FlockDecoder d(f);
  auto recs = records_of(d, encode_flock_record(r, f));
  ASSERT_EQ(recs.size(), 1u);
  // 14-bit words: position step 4*36/32768 in = 0.11 mm, quaternion step 1.2e-4
  expect_pose_near(recs[0], r, 3e-4, 3e-4);
}

TEST(FlockDecoder, ResyncOnThePhasingBit) {
  const FlockFormat f{36, true, 1};
  const Bytes good = encode_flock_record(sample_record(2), f);
  const Bytes cut(good.begin(), good.begin() + 6);
  FlockDecoder d(f);
  std::vector<TrackerRecord> recs;
  for (auto byte : Bytes{0x01, 0x02, 0x7F} + good + cut + good + Bytes{0x85, 0x01} + good) {
    auto got = records_of(d, Bytes{byte});
    recs.insert(recs.end(), got.begin(), got.end());
  }
  ASSERT_EQ(recs.size(), 3u);
  for (const auto& r : recs) EXPECT_EQ(r.station, 2);
  EXPECT_GE(d.resyncs(), 3u);
  EXPECT_GE(d.bad_records(), 2u);
}

namespace {

// Two long runs of noise, each followed by records, fed in reads of `chunk` bytes (an odd
// size, so records straddle reads): every record must come out, and each run of noise
// must count as exactly one resync, however many reads it spans.
template <typename Decoder, typename Encode>
void expect_records_after_long_noise(Decoder& d, Encode encode, std::size_t chunk, double tol) {
  constexpr int kPerRun = 40;
  Bytes stream;
  std::vector<TrackerRecord> sent;
  for (int run = 0; run < 2; ++run) {
    const Bytes noise = test::noise_without_records(64 * 1024);
    stream.insert(stream.end(), noise.begin(), noise.end());
    for (int i = 0; i < kPerRun; ++i) {
      sent.push_back(test::stream_record(run * kPerRun + i));
      const Bytes r = encode(sent.back());
      stream.insert(stream.end(), r.begin(), r.end());
    }
  }
  std::vector<TrackerRecord> got;
  for (std::size_t at = 0; at < stream.size(); at += chunk) {
    const Bytes read(stream.begin() + static_cast<std::ptrdiff_t>(at),
                     stream.begin() + static_cast<std::ptrdiff_t>(std::min(stream.size(), at + chunk)));
    auto recs = records_of(d, read);
    got.insert(got.end(), recs.begin(), recs.end());
  }
  ASSERT_EQ(got.size(), sent.size()) << "read size " << chunk;
  for (std::size_t i = 0; i < sent.size(); ++i) expect_pose_near(got[i], sent[i], tol, tol);
  EXPECT_EQ(d.resyncs(), 2u) << "read size " << chunk;
  EXPECT_EQ(d.bad_records(), 0u) << d.last_problem();
}

}  // namespace

TEST(FastrakDecoder, EveryRecordAfterLongNoiseAndOneResyncPerRun) {
  const FastrakFormat f{Units::Centimetres, {FastrakExtra::Timestamp}, true};
  for (std::size_t chunk : {std::size_t{777}, std::size_t{4096}, std::size_t{1} << 20}) {
    FastrakDecoder d(f);
    expect_records_after_long_noise(d, [&](const TrackerRecord& r) { return encode_fastrak_record(r, f); },
                                    chunk, 1e-6);
  }
}

TEST(LibertyDecoder, EveryRecordAfterLongNoiseAndOneResyncPerRun) {
  const LibertyFormat f{Units::Centimetres, {LibertyExtra::Timestamp}};
  for (std::size_t chunk : {std::size_t{777}, std::size_t{4096}, std::size_t{1} << 20}) {
    LibertyDecoder d(f);
    expect_records_after_long_noise(d, [&](const TrackerRecord& r) { return encode_liberty_record(r, f); },
                                    chunk, 1e-6);
  }
}

TEST(FlockDecoder, EveryRecordAfterLongNoiseAndOneResyncPerRun) {
  const FlockFormat f{36, true, 1};
  for (std::size_t chunk : {std::size_t{777}, std::size_t{4096}, std::size_t{1} << 20}) {
    FlockDecoder d(f);
    // 14-bit words: see GroupModeAddressAndNegativeValues.
    expect_records_after_long_noise(d, [&](const TrackerRecord& r) { return encode_flock_record(r, f); },
                                    chunk, 3e-4);
  }
}
