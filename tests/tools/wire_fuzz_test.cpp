// Hostile wire input at running clients, inside this test's private network namespace:
// about 3,000 malformed, mutated and forged messages are published next to good ones at
// `covtrack echo`, `covtrack echo --json`, `covtrack view --live` and a client-library
// Subscriber, all running at once. Each must still be running at the end (it stops on
// SIGINT with exit code 0), must have counted every bad message, and must have delivered
// every good one in order, with its loss counter untouched by forged sequence numbers.
//
// The cases: string lengths of 0, -1, INT_MIN and INT_MAX; wrong type fingerprints;
// truncations; trailing bytes, once 200 KB of them (a fragmented datagram); NaN in the
// covariance, position and quaternion; invalid UTF-8 and control characters in names and
// frames; a message naming another stream than its channel; channel names that break
// the rules; forged sequence numbers far ahead, far behind and repeated; malformed
// heartbeats; and random bit flips, cuts and insertions of a valid pose.
#include <csignal>
#include <climits>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "covtrack/client/subscriber.hpp"
#include "covtrack/device_status_t.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/pose_message.hpp"
#include "covtrack/truth_pose_t.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
using covtrack::testing::Child;
using covtrack::testing::Message;
using covtrack::testing::encode;
using covtrack::testing::eventually;

const std::string kUrl = "udpm://239.255.76.67:7715?ttl=0&recv_buf_size=4194304";
const std::string kGood = covtrack::pose_channel("fuzz", "good");
const std::string kMutated = covtrack::pose_channel("fuzz", "mut");
const std::string kEnd = covtrack::pose_channel("fuzz", "end");
constexpr std::int64_t kGoodCount = 600;

covtrack::pose_cov_t pose(const std::string& sensor, std::int64_t sequence) {
  covtrack::pose_cov_t m{};
  m.device = "fuzz";
  m.sensor = sensor;
  m.parent_frame = "world";
  m.child_frame = sensor;
  m.sequence = sequence;
  m.measurement_time_us = m.publish_time_us = 1'700'000'000'000'000 + sequence * 1000;
  covtrack::Pose T = covtrack::Pose::Identity();
  T.translation() = covtrack::Vec3(0.1, 0.2, 1.5);
  covtrack::set_pose(m, T, covtrack::Mat6::Identity() * 1e-6);
  return m;
}

void put_int32(std::vector<std::byte>& b, std::size_t at, std::int32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = std::byte((static_cast<std::uint32_t>(v) >> (24 - 8 * i)) & 0xff);
}

// pose_cov_t on the wire: fingerprint, three int64, then device, sensor, frames.
constexpr std::size_t kDeviceLengthAt = 8 + 24;

// The messages and what a correct receiver makes of them.
struct Corpus {
  std::vector<Message> messages;
  std::int64_t good_rejected = 0;  // malformed or invalid on fuzz/good
  std::int64_t good_foreign = 0;   // valid, with a forged sequence number, on fuzz/good
  std::int64_t mutated = 0;        // on fuzz/mut: each received, rejected or foreign
  std::int64_t unowned = 0;        // rejected heartbeats and channels that name no stream
};

// One bad message on fuzz/good for `k`, cycling through the cases; true if it is valid
// (foreign by its sequence number), false if it must be rejected.
std::pair<std::vector<std::byte>, bool> adversarial(int k, std::int64_t last_good, std::mt19937& rng) {
  auto bytes = encode(pose("good", last_good));
  auto with = [&](auto change) {
    auto m = pose("good", -5);  // invalid values: a sequence number off the track, so only "rejected" counts
    change(m);
    return encode(m);
  };
  switch (k % 17) {
    case 0: put_int32(bytes, kDeviceLengthAt, 0); return {bytes, false};
    case 1: put_int32(bytes, kDeviceLengthAt, -1); return {bytes, false};
    case 2: put_int32(bytes, kDeviceLengthAt, INT_MIN); return {bytes, false};
    case 3: put_int32(bytes, kDeviceLengthAt, INT_MAX); return {bytes, false};
    case 4: bytes[2] ^= std::byte{0x40}; return {bytes, false};  // fingerprint
    case 5: return {encode(covtrack::truth_pose_t{}), false};    // another type
    case 6: bytes.resize(rng() % bytes.size()); return {bytes, false};
    case 7: bytes.resize(bytes.size() + (k % 5 == 0 ? 200'000 : 3)); return {bytes, false};
    case 8: return {with([](auto& m) { m.covariance[14] = NAN; }), false};
    case 9: return {with([](auto& m) { m.position_m[1] = NAN; }), false};
    case 10: return {with([](auto& m) { m.orientation_wxyz[0] = NAN; }), false};
    case 11: return {with([](auto& m) { m.parent_frame = "w\xff\xfe"; }), false};
    case 12: return {with([](auto& m) { m.child_frame = "good\x1b[2J"; }), false};
    case 13: return {with([](auto& m) { m.device = "other"; }), false};  // names another stream
    case 14: return {encode(pose("good", last_good + 670'000'000'000'000'000)), true};
    case 15: return {encode(pose("good", std::numeric_limits<std::int64_t>::min())), true};
    default: return {encode(pose("good", last_good)), true};  // a repeat of the last good one
  }
}

// A valid pose on fuzz/mut with 1-4 bit flips, and sometimes a cut or an inserted byte.
std::vector<std::byte> mutated(std::int64_t n, std::mt19937& rng) {
  auto bytes = encode(pose("mut", n));
  for (int f = 1 + static_cast<int>(rng() % 4); f > 0; --f) bytes[rng() % bytes.size()] ^= std::byte(1u << (rng() % 8));
  if (rng() % 8 == 0) bytes.resize(rng() % bytes.size());
  if (rng() % 8 == 0) bytes.insert(bytes.begin() + static_cast<long>(rng() % bytes.size()), std::byte(rng()));
  return bytes;
}

// Heartbeats of device "fuzz" that must be rejected, and pose channels that break the rules.
Message unowned(int k) {
  covtrack::device_status_t st{};
  st.device = "fuzz";
  st.heartbeat_period_us = 1'000'000;
  const std::string status = covtrack::status_channel("fuzz");
  switch (k % 8) {
    case 0: {
      auto bytes = encode(st);
      put_int32(bytes, 8 + 8, 0);  // fingerprint, time_us, then the device's length
      return {status, bytes};
    }
    case 1: return {status, encode(pose("good", 0))};
    case 2: st.rate_hz = NAN; return {status, encode(st)};
    case 3: st.host = "pc\xc0\xaf"; return {status, encode(st)};
    case 4: st.heartbeat_period_us = -1; return {status, encode(st)};
    case 5: return {"covtrack/pose/fu zz/good", encode(pose("good", 0))};
    case 6: return {"covtrack/pose/fuzz", encode(pose("good", 0))};
    default: return {"covtrack/pose/fuzz/good/extra", encode(pose("good", 0))};
  }
}

Corpus make_corpus() {
  std::mt19937 rng(2121);
  Corpus c;
  std::int64_t mutated_sent = 0;
  for (std::int64_t i = 0; i < kGoodCount; ++i) {
    c.messages.push_back({kGood, encode(pose("good", i))});
    auto [bytes, valid] = adversarial(static_cast<int>(i), i, rng);
    c.messages.push_back({kGood, bytes});
    (valid ? c.good_foreign : c.good_rejected) += 1;
    for (int m = 0; m < 3; ++m) c.messages.push_back({kMutated, mutated(mutated_sent++, rng)});
    if (i % 8 == 0) {
      c.messages.push_back(unowned(static_cast<int>(i / 8)));
      ++c.unowned;
    }
  }
  c.mutated = mutated_sent;
  return c;
}

// A receiver's counts, from its summary or from the library.
struct Counts {
  std::int64_t received = -1, lost = -1, rejected = -1, foreign = -1, restarts = -1;
};
struct Report {
  std::map<std::string, Counts> streams;
  std::int64_t rejected_total = -1;
};

// The summary `covtrack echo` and `covtrack view` print when they end.
Report parse_summary(const std::string& output, const std::string& prefix) {
  Report r;
  const std::regex stream(prefix + R"(([\w-]+/[\w-]+): received (\d+), lost (\d+), rejected (\d+), foreign (\d+), restarts (\d+))");
  const std::regex total(prefix + R"(rejected messages: (\d+))");
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (std::regex_search(line, m, stream))
      r.streams[m[1]] = {std::stoll(m[2]), std::stoll(m[3]), std::stoll(m[4]), std::stoll(m[5]), std::stoll(m[6])};
    else if (std::regex_search(line, m, total))
      r.rejected_total = std::stoll(m[1]);
  }
  return r;
}

Report library_report(const covtrack::client::Subscriber& sub) {
  Report r;
  for (const auto& s : sub.streams())
    r.streams[s.id.key()] = {s.counters.received, s.counters.lost, s.counters.rejected, s.counters.foreign,
                             s.counters.restarts};
  r.rejected_total = sub.rejections().total;
  return r;
}

// Every receiver must account for the corpus exactly.
void expect_accounted(const Report& r, const Corpus& c, const std::string& who) {
  SCOPED_TRACE(who);
  ASSERT_TRUE(r.streams.count("fuzz/good") && r.streams.count("fuzz/mut") && r.streams.count("fuzz/end"));
  const Counts& good = r.streams.at("fuzz/good");
  EXPECT_EQ(good.received, kGoodCount);  // every good message delivered
  EXPECT_EQ(good.rejected, c.good_rejected);
  EXPECT_EQ(good.foreign, c.good_foreign);
  EXPECT_EQ(good.lost, 0);  // forged numbers are no loss
  EXPECT_EQ(good.restarts, 0);
  const Counts& mut = r.streams.at("fuzz/mut");
  EXPECT_EQ(mut.received + mut.rejected + mut.foreign, c.mutated);  // each mutated message counted once
  EXPECT_GT(mut.rejected, c.mutated / 10);
  EXPECT_EQ(r.streams.at("fuzz/end").received, 1);
  EXPECT_EQ(r.rejected_total, c.good_rejected + mut.rejected + c.unowned);
}

}  // namespace

TEST(WireFuzz, ClientsSurviveCountEveryBadMessageAndDeliverEveryGoodOne) {
  const fs::path dir = covtrack::testing::make_temp_dir();
  const Corpus corpus = make_corpus();
  std::printf("corpus: %zu messages: %lld good, %lld malformed or invalid and %lld forged on fuzz/good, "
              "%lld mutated, %lld bad heartbeats or channels\n",
              corpus.messages.size(), static_cast<long long>(kGoodCount), static_cast<long long>(corpus.good_rejected),
              static_cast<long long>(corpus.good_foreign), static_cast<long long>(corpus.mutated),
              static_cast<long long>(corpus.unowned));

  Child table({COVTRACK_CLI, "echo", "--lcm-url", kUrl}, dir / "table.out");
  Child json({COVTRACK_CLI, "echo", "--json", "--lcm-url", kUrl}, dir / "json.out");
  Child view({COVTRACK_CLI, "view", COVTRACK_SOURCE_DIR "/config/scenes/head_and_world.toml", "--live", "--lcm-url",
              kUrl, "--png", (dir / "view.png").string(), "--duration", "600", "--fps", "5"},
             dir / "view.out");
  auto opened = covtrack::client::Subscriber::open({.lcm_url = kUrl});
  ASSERT_TRUE(opened) << opened.error().message;
  auto& library = **opened;
  // Each prints a line once it receives (and a SIGINT ends it cleanly).
  for (const Child* c : {&table, &json})
    ASSERT_TRUE(eventually([&] { return c->output().find("listening on") != std::string::npos; })) << c->output();
  ASSERT_TRUE(eventually([&] { return view.output().find("following the streams") != std::string::npos; }))
      << view.output();

  // In batches, each once the library has accounted for the one before (no receiver's
  // socket buffer overflows); the others keep the same pace.
  lcm::LCM publisher(kUrl);
  ASSERT_TRUE(publisher.good());
  const auto accounted = [&] {
    std::int64_t n = library.rejections().total;
    for (const auto& s : library.streams()) n += s.counters.received + s.counters.foreign;
    return n;
  };
  for (std::size_t i = 0; i < corpus.messages.size(); ++i) {
    const Message& m = corpus.messages[i];
    publisher.publish(m.channel, m.bytes.data(), static_cast<unsigned>(m.bytes.size()));
    if (i % 200 == 199) {
      ASSERT_TRUE(eventually([&] { return accounted() >= static_cast<std::int64_t>(i + 1); }))
          << accounted() << " of " << i + 1;
    }
  }
  const auto end = encode(pose("end", 0));
  publisher.publish(kEnd, end.data(), static_cast<unsigned>(end.size()));
  // Handled in order: once a receiver has the end marker it has everything before it.
  ASSERT_TRUE(eventually([&] { return library.stream({"fuzz", "end"}).has_value(); }));
  ASSERT_TRUE(eventually([&] { return json.output().find(R"("sensor":"end")") != std::string::npos; }));
  ASSERT_TRUE(eventually([&] { return table.output().find("\nfuzz/end ") != std::string::npos; }));

  for (Child* c : {&table, &json, &view}) c->signal(SIGINT);
  EXPECT_EQ(table.wait(), 0) << table.output().substr(0, 2000);
  EXPECT_EQ(json.wait(), 0);
  EXPECT_EQ(view.wait(), 0) << view.output();
  library.stop();

  const Report lib = library_report(library);
  const Counts mut_lib = lib.streams.count("fuzz/mut") ? lib.streams.at("fuzz/mut") : Counts{};
  std::printf("library Subscriber: fuzz/mut received %lld, rejected %lld, foreign %lld; rejected in all: %s\n",
              static_cast<long long>(mut_lib.received), static_cast<long long>(mut_lib.rejected),
              static_cast<long long>(mut_lib.foreign), library.rejections().summary().substr(0, 300).c_str());
  expect_accounted(lib, corpus, "library Subscriber");
  expect_accounted(parse_summary(table.output(), "covtrack echo: "), corpus, "covtrack echo");
  expect_accounted(parse_summary(json.output(), "covtrack echo: "), corpus, "covtrack echo --json");
  expect_accounted(parse_summary(view.output(), "covtrack view: "), corpus, "covtrack view --live");
  EXPECT_TRUE(fs::exists(dir / "view.png"));

  // --json: one parseable line per delivered message, the good stream whole and in order.
  std::int64_t next_good = 0, lines = 0;
  std::istringstream out(json.output());
  for (std::string line; std::getline(out, line);) {
    if (!line.starts_with("{")) continue;
    const auto j = nlohmann::json::parse(line);  // throws (fails the test) on a broken line
    ++lines;
    if (j["sensor"] == "good") {
      EXPECT_EQ(j["sequence"].get<std::int64_t>(), next_good++);
    }
  }
  EXPECT_EQ(next_good, kGoodCount);
  const Counts mut = parse_summary(json.output(), "covtrack echo: ").streams["fuzz/mut"];
  EXPECT_EQ(lines, kGoodCount + mut.received + 1);
  fs::remove_all(dir);
}
