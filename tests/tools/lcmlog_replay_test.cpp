// Record and replay in one process over memq://: the recorder's log holds exactly what was
// published, and replay publishes the log back with its filters, start offset and pacing.
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <limits>
#include <thread>

#include <gtest/gtest.h>

#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/lcmlog/log_writer.hpp"
#include "covtrack/lcmlog/recorder.hpp"
#include "covtrack/lcmlog/replayer.hpp"
#include "test_support.hpp"

namespace {
using namespace covtrack::lcmlog;
using covtrack::testing::Message;

// Collects everything published on a memq LCM; memq delivers on handle() in this thread.
struct MemqSink {
  explicit MemqSink(lcm::LCM& lcm) : lcm(lcm) {
    lcm.subscribe(".*", &MemqSink::on_message, this)->setQueueCapacity(1 << 20);
  }
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const auto* data = static_cast<const std::byte*>(rbuf->data);
    got.push_back({channel, {data, data + rbuf->data_size}});
  }
  void drain() {
    while (lcm.handleTimeout(0) > 0) {
    }
  }
  lcm::LCM& lcm;
  std::vector<Message> got;
};

class ReplayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = covtrack::testing::make_temp_dir();
    messages_ = covtrack::testing::make_messages(400);
    log_ = dir_ / "ten-seconds.lcmlog";
    // 400 events over 10 s of log time: event i at 25 ms * i.
    auto writer = LogWriter::create(log_.string(), false);
    ASSERT_TRUE(writer);
    for (std::size_t i = 0; i < messages_.size(); ++i)
      ASSERT_TRUE(writer->write(kT0 + static_cast<std::int64_t>(i) * 25'000,
                                messages_[i].channel, messages_[i].bytes));
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  ReplaySummary replay_into(MemqSink& sink, const ReplayOptions& options) {
    auto reader = LogReader::open(log_.string());
    EXPECT_TRUE(reader);
    std::atomic<bool> stop{false};
    auto summary = replay(*reader, sink.lcm, options, stop);
    EXPECT_TRUE(summary) << summary.error().message;
    sink.drain();
    return *summary;
  }

  static constexpr std::int64_t kT0 = 1'700'000'000'000'000;
  std::filesystem::path dir_, log_;
  std::vector<Message> messages_;
};

TEST_F(ReplayTest, FullSpeedPublishesEveryEventInOrder) {
  lcm::LCM lcm("memq://");
  MemqSink sink(lcm);
  const auto summary = replay_into(sink, {.speed = 0});
  EXPECT_EQ(summary.events_published, messages_.size());
  EXPECT_TRUE(summary.damage.empty());
  EXPECT_EQ(sink.got, messages_);
}

// `covtrack record` can write a first event timed after the next few (it stamps in the
// order LCM hands messages over); a damaged log can hold any timestamp at all. Every
// event is still published, in file order, as lcm-logplayer does.
TEST_F(ReplayTest, EventsTimedBeforeTheFirstOrWildlyArePublishedToo) {
  const auto path = dir_ / "out-of-order.lcmlog";
  const std::vector<std::int64_t> times = {kT0 + 3000, kT0, kT0 + 1000, kT0 + 2000, kT0 + 4000,
                                           std::numeric_limits<std::int64_t>::min(), kT0 + 5000,
                                           std::numeric_limits<std::int64_t>::max(), kT0 + 6000};
  {
    auto writer = LogWriter::create(path.string(), false);
    ASSERT_TRUE(writer);
    for (std::size_t i = 0; i < times.size(); ++i)
      ASSERT_TRUE(writer->write(times[i], messages_[i].channel, messages_[i].bytes));
  }
  const std::vector<Message> expected(messages_.begin(), messages_.begin() + static_cast<std::ptrdiff_t>(times.size()));
  for (const double speed : {0.0, 1.0}) {
    lcm::LCM lcm("memq://");
    MemqSink sink(lcm);
    auto reader = LogReader::open(path.string());
    ASSERT_TRUE(reader);
    std::atomic<bool> stop{false};
    // At speed 1 the event timed at the end of time would be due in ~300,000 years; it is
    // held at most a day, so stop the replay (from its progress reports, which come while
    // it waits) once the seven events before it came out.
    const auto summary = replay(*reader, sink.lcm, {.speed = speed}, stop, [&](const ReplayProgress& p) {
      if (speed > 0 && p.events_published >= 7) stop = true;
    });
    ASSERT_TRUE(summary) << summary.error().message;
    sink.drain();
    if (speed == 0) {
      EXPECT_EQ(summary->events_published, times.size());
      EXPECT_EQ(sink.got, expected);
    } else {
      ASSERT_GE(sink.got.size(), 7u);  // up to the one timed at the end of time
      EXPECT_TRUE(std::equal(sink.got.begin(), sink.got.end(), expected.begin()));
    }
  }
}

TEST_F(ReplayTest, ChannelFilterKeepsOnlyMatchingChannels) {
  lcm::LCM lcm("memq://");
  MemqSink sink(lcm);
  replay_into(sink, {.speed = 0, .channels = "covtrack/pose/sim/(head|wand)"});
  std::vector<Message> expected;
  for (const auto& m : messages_)
    if (m.channel == "covtrack/pose/sim/head" || m.channel == "covtrack/pose/sim/wand")
      expected.push_back(m);
  ASSERT_EQ(expected.size(), 200u);
  EXPECT_EQ(sink.got, expected);
}

TEST_F(ReplayTest, StartSkipsTheFirstSecondsOfTheLog) {
  lcm::LCM lcm("memq://");
  MemqSink sink(lcm);
  replay_into(sink, {.speed = 0, .start_s = 2.5});  // events 100.. are at >= 2.5 s
  EXPECT_EQ(sink.got, std::vector<Message>(messages_.begin() + 100, messages_.end()));
}

TEST_F(ReplayTest, SpeedScalesTheOriginalTiming) {
  lcm::LCM lcm("memq://");
  MemqSink sink(lcm);
  // The last 2 s of log time at 8x must take 0.25 s: not less (the pacing), and not
  // wildly more (no per-event drift).
  const auto started = std::chrono::steady_clock::now();
  replay_into(sink, {.speed = 8, .start_s = 7.975});
  const double took_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  EXPECT_EQ(sink.got.size(), 81u);
  EXPECT_GE(took_s, 0.25);
  EXPECT_LT(took_s, 1.0);
}

TEST_F(ReplayTest, LoopReplaysUntilStopped) {
  lcm::LCM lcm("memq://");
  MemqSink sink(lcm);
  auto reader = LogReader::open(log_.string());
  ASSERT_TRUE(reader);
  std::atomic<bool> stop{false};
  std::uint64_t seen = 0;
  auto summary = replay(*reader, lcm, {.speed = 0, .loop = true}, stop,
                        [&](const ReplayProgress& p) {
                          seen = p.events_published;
                          if (p.events_published >= 3 * messages_.size()) stop = true;
                        });
  ASSERT_TRUE(summary);
  EXPECT_TRUE(summary->stopped);
  EXPECT_GE(summary->passes, 3u);
  EXPECT_GE(summary->events_published, 3 * messages_.size());
  EXPECT_EQ(seen, summary->events_published);
}

TEST_F(ReplayTest, DamagedLogReplaysEverythingIntactAndReportsTheDamage) {
  const auto size = std::filesystem::file_size(log_);
  std::filesystem::resize_file(log_, size - 10);  // cut the last event
  lcm::LCM lcm("memq://");
  MemqSink sink(lcm);
  const auto summary = replay_into(sink, {.speed = 0});
  EXPECT_EQ(sink.got, std::vector<Message>(messages_.begin(), messages_.end() - 1));
  ASSERT_EQ(summary.damage.size(), 1u);
  EXPECT_TRUE(summary.damage[0].truncated);
  EXPECT_EQ(summary.damage[0].offset + summary.damage[0].skipped_bytes, size - 10);
}

TEST(RecorderTest, RecordsEverythingPublishedUntilStopped) {
  const auto dir = covtrack::testing::make_temp_dir();
  const auto path = dir / "memq.lcmlog";
  const auto messages = covtrack::testing::make_messages(2000);
  lcm::LCM lcm("memq://");
  auto writer = LogWriter::create(path.string(), false);
  ASSERT_TRUE(writer);
  auto recorder = Recorder::start(lcm, *writer, "covtrack/pose/.*");
  ASSERT_TRUE(recorder) << recorder.error().message;
  // memq queues published messages for handle(): publish all first (more than LCM's
  // default queue of 30), then stop the recorder at once; it must still write them all.
  for (const auto& m : messages) lcm.publish(m.channel, m.bytes.data(), m.bytes.size());
  int stop[2];
  ASSERT_EQ(::pipe(stop), 0);
  ASSERT_EQ(::write(stop[1], "x", 1), 1);
  auto summary = (*recorder)->run(stop[0], std::nullopt);
  ::close(stop[0]);
  ::close(stop[1]);
  ASSERT_TRUE(summary) << summary.error().message;

  std::vector<Message> poses;
  for (const auto& m : messages)
    if (m.channel.starts_with("covtrack/pose/")) poses.push_back(m);
  EXPECT_EQ(covtrack::testing::read_log(path), poses);
  EXPECT_EQ(summary->events, poses.size());
  auto log = LogReader::open(path.string());
  ASSERT_TRUE(log) << log.error().message;
  std::int64_t previous = 0;
  while (auto event = log->next()) {
    EXPECT_GE(event->timestamp_us, previous) << "event " << event->event_number;
    previous = event->timestamp_us;
  }
  EXPECT_EQ(summary->events_per_channel.size(), 3u);
  EXPECT_EQ(summary->events_per_channel.at("covtrack/pose/sim/head"), 500u);
  EXPECT_EQ(summary->bytes, std::filesystem::file_size(path));
  std::filesystem::remove_all(dir);
}

// Receive stamps out of order, as the kernel gives a session's first datagrams: each
// event keeps its place, none is stamped before the one written ahead of it.
TEST(RecorderTest, ReceiveStampsOutOfOrderAreWrittenAscending) {
  AscendingStamps stamps;
  std::vector<std::int64_t> written;
  for (std::int64_t received : {1'000'300, 1'000'100, 1'000'200, 1'000'400, 1'000'350, 1'000'500})
    written.push_back(stamps.stamp(received));
  EXPECT_EQ(written, (std::vector<std::int64_t>{1'000'300, 1'000'300, 1'000'300, 1'000'400, 1'000'400, 1'000'500}));
  EXPECT_EQ(stamps.restamped(), 3u);
  AscendingStamps in_order;
  for (std::int64_t received : {5, 5, 6, 9}) EXPECT_EQ(in_order.stamp(received), received);
  EXPECT_EQ(in_order.restamped(), 0u);
}

TEST(RecorderTest, StopsAfterTheDuration) {
  const auto dir = covtrack::testing::make_temp_dir();
  lcm::LCM lcm("memq://");
  auto writer = LogWriter::create((dir / "d.lcmlog").string(), false);
  ASSERT_TRUE(writer);
  auto recorder = Recorder::start(lcm, *writer, ".*");
  ASSERT_TRUE(recorder);
  auto summary = (*recorder)->run(-1, 0.2);
  ASSERT_TRUE(summary);
  EXPECT_GE(summary->duration_s, 0.2);
  EXPECT_LT(summary->duration_s, 2.0);
  EXPECT_EQ(summary->events, 0u);
  std::filesystem::remove_all(dir);
}

}  // namespace
