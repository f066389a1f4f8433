// `covtrack record` and `covtrack replay` as processes on a real multicast LCM, inside the
// test's private network namespace (tests/netns_run.sh), next to LCM's own lcm-logger and
// lcm-logplayer.
#include <csignal>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "test_support.hpp"

namespace {
namespace fs = std::filesystem;
using covtrack::testing::Child;
using covtrack::testing::Collector;
using covtrack::testing::Message;
using covtrack::testing::eventually;

// One port per test: LCM 1.3.1 groups on one port cross-talk.
std::string url_for(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=4194304";
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = covtrack::testing::make_temp_dir(); }
  void TearDown() override { fs::remove_all(dir_); }

  // Publishes in batches of 20, each only after the log holds the previous one: a
  // recorder that keeps LCM's default queue of 30 (lcm-logger) would drop the rest.
  // `nudge` runs while waiting (lcm-logger writes its buffered tail only when a later
  // message arrives). Only covtrack/ channels are counted in the log.
  void publish_all(const std::string& url, const std::vector<Message>& messages,
                   const fs::path& log,
                   const std::function<bool(const Message&)>& recorded = {},
                   const std::function<void()>& nudge = {}) {
    lcm::LCM publisher(url);
    ASSERT_TRUE(publisher.good());
    auto in_log = [&] {
      std::size_t n = 0;
      for (const auto& m : covtrack::testing::read_log(log)) n += m.channel.starts_with("covtrack/");
      return n;
    };
    std::size_t expected = 0;
    for (std::size_t i = 0; i < messages.size(); ++i) {
      if (!recorded || recorded(messages[i])) ++expected;
      publisher.publish(messages[i].channel, messages[i].bytes.data(),
                        static_cast<unsigned>(messages[i].bytes.size()));
      if (i % 20 == 19 || i + 1 == messages.size()) {
        ASSERT_TRUE(eventually([&] {
          if (nudge) nudge();
          return in_log() >= expected;
        })) << in_log() << " of " << expected << " in the log";
      }
    }
  }

  // `covtrack record` of `messages`; returns its output (the summary).
  std::string record_with_cli(const std::string& url, const std::vector<Message>& messages,
                              const fs::path& log, std::vector<std::string> extra = {}) {
    std::vector<std::string> argv = {COVTRACK_CLI, "record", log.string(), "--lcm-url", url};
    argv.insert(argv.end(), extra.begin(), extra.end());
    Child recorder(argv, dir_ / "record.out");
    EXPECT_TRUE(eventually([&] { return recorder.output().find("recording") != std::string::npos; }))
        << recorder.output();
    publish_all(url, messages, log);
    recorder.signal(SIGINT);
    EXPECT_EQ(recorder.wait(), 0) << recorder.output();
    return recorder.output();
  }

  // Runs a replayer process to its end while collecting; returns the exit code.
  int replay_and_collect(const std::string& url, std::vector<std::string> argv,
                         std::size_t expected, std::vector<Message>& got, std::string& output) {
    Collector collector(url);
    auto [code, out] = covtrack::testing::run(argv, dir_ / "replay.out");
    output = out;
    EXPECT_TRUE(collector.wait_for(expected)) << collector.size() << " of " << expected;
    got = collector.take();
    return code;
  }

  fs::path dir_;
};

TEST_F(CliTest, RecordThenReplayGivesIdenticalPayloadsInOrder) {
  const std::string url = url_for(7701);
  const auto messages = covtrack::testing::make_messages(3000);
  const fs::path log = dir_ / "session.lcmlog";
  const std::string summary = record_with_cli(url, messages, log);
  EXPECT_NE(summary.find("3000 events"), std::string::npos) << summary;
  EXPECT_NE(summary.find("covtrack/raw/fastrak"), std::string::npos) << summary;
  EXPECT_EQ(covtrack::testing::read_log(log), messages);

  std::vector<Message> got;
  std::string output;
  const int code = replay_and_collect(
      url, {COVTRACK_CLI, "replay", log.string(), "--speed", "0", "--lcm-url", url},
      messages.size(), got, output);
  EXPECT_EQ(code, 0) << output;
  EXPECT_EQ(got, messages);
  // stderr is a file here, not a terminal: no progress line.
  EXPECT_EQ(output.find('\r'), std::string::npos);
}

TEST_F(CliTest, RecordKeepsOnlyMatchingChannelsAndRefusesToOverwrite) {
  const std::string url = url_for(7702);
  const auto messages = covtrack::testing::make_messages(400);
  const fs::path log = dir_ / "raw.lcmlog";
  std::vector<Message> raw;
  for (const auto& m : messages)
    if (m.channel.starts_with("covtrack/raw/")) raw.push_back(m);

  std::vector<std::string> argv = {COVTRACK_CLI, "record", log.string(), "--lcm-url", url,
                                   "--channels", "covtrack/raw/.*"};
  {
    Child recorder(argv, dir_ / "record.out");
    ASSERT_TRUE(eventually([&] { return recorder.output().find("recording") != std::string::npos; }));
    publish_all(url, messages, log,
                [](const Message& m) { return m.channel.starts_with("covtrack/raw/"); });
    recorder.signal(SIGTERM);
    EXPECT_EQ(recorder.wait(), 0) << recorder.output();
  }
  EXPECT_EQ(covtrack::testing::read_log(log), raw);

  const auto before = covtrack::testing::read_file(log);
  auto [code, out] = covtrack::testing::run(argv, dir_ / "again.out");
  EXPECT_EQ(code, 1);
  EXPECT_NE(out.find("--force"), std::string::npos) << out;
  EXPECT_EQ(covtrack::testing::read_file(log), before);

  argv.insert(argv.end(), {"--force", "--duration", "0.2"});
  auto [forced, forced_out] = covtrack::testing::run(argv, dir_ / "forced.out");
  EXPECT_EQ(forced, 0) << forced_out;
  EXPECT_NE(forced_out.find("0 events"), std::string::npos) << forced_out;
  EXPECT_EQ(fs::file_size(log), 0u);
}

TEST_F(CliTest, CovtrackLogPlaysWithLcmLogplayer) {
  const std::string url = url_for(7703);
  const auto messages = covtrack::testing::make_messages(1000);
  const fs::path log = dir_ / "for-logplayer.lcmlog";
  record_with_cli(url, messages, log);

  std::vector<Message> got;
  std::string output;
  const int code = replay_and_collect(url, {LCM_LOGPLAYER, "-s", "4", "--lcm-url=" + url, log.string()},
                                      messages.size(), got, output);
  EXPECT_EQ(code, 0) << output;
  EXPECT_EQ(got, messages);
}

TEST_F(CliTest, LcmLoggerLogReplaysWithCovtrack) {
  const std::string url = url_for(7704);
  const auto messages = covtrack::testing::make_messages(1000);
  const fs::path log = dir_ / "from-lcm-logger.lcmlog";
  // lcm-logger 1.3.1 lists -l in its help but rejects it: use the long option.
  Child logger({LCM_LOGGER, "--lcm-url=" + url, "--flush-interval=10", "-q", log.string()},
               dir_ / "logger.out");
  // lcm-logger says nothing when ready: probe until a probe message reaches its log.
  lcm::LCM probe(url);
  auto nudge = [&] { probe.publish("probe", "x", 1); };
  ASSERT_TRUE(eventually([&] {
    nudge();
    return covtrack::testing::count_events(log) > 0;
  })) << logger.output();
  publish_all(url, messages, log, {}, nudge);
  logger.signal(SIGINT);
  logger.wait();

  std::vector<Message> got;
  std::string output;
  const int code = replay_and_collect(url,
                                      {COVTRACK_CLI, "replay", log.string(), "--speed", "0",
                                       "--channels", "covtrack/.*", "--lcm-url", url},
                                      messages.size(), got, output);
  EXPECT_EQ(code, 0) << output;
  EXPECT_EQ(got, messages);  // the probes are filtered out
}

TEST_F(CliTest, DamagedLogsReplayUpToTheDamageAndExitWith3) {
  const std::string url = url_for(7705);
  const auto messages = covtrack::testing::make_messages(600);
  const fs::path log = dir_ / "good.lcmlog";
  record_with_cli(url, messages, log);
  // Event offsets, to cut and overwrite at known places.
  std::vector<std::uint64_t> offsets;
  {
    auto reader = covtrack::lcmlog::LogReader::open(log.string());
    ASSERT_TRUE(reader);
    while (auto e = reader->next()) offsets.push_back(e->offset);
  }
  ASSERT_EQ(offsets.size(), messages.size());

  const fs::path truncated = dir_ / "truncated.lcmlog";
  fs::copy_file(log, truncated);
  fs::resize_file(truncated, offsets[500] + 30);
  std::vector<Message> got;
  std::string output;
  int code = replay_and_collect(
      url, {COVTRACK_CLI, "replay", truncated.string(), "--speed", "0", "--lcm-url", url}, 500,
      got, output);
  EXPECT_EQ(code, 3) << output;
  EXPECT_EQ(got, std::vector<Message>(messages.begin(), messages.begin() + 500));
  EXPECT_NE(output.find("byte offset " + std::to_string(offsets[500])), std::string::npos)
      << output;
  EXPECT_NE(output.find("500 events"), std::string::npos) << output;

  const fs::path corrupted = dir_ / "corrupted.lcmlog";
  fs::copy_file(log, corrupted);
  {
    std::fstream f(corrupted, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(offsets[300] - 10));
    for (int i = 0; i < 40; ++i) f.put('G');
  }
  code = replay_and_collect(
      url, {COVTRACK_CLI, "replay", corrupted.string(), "--speed", "0", "--lcm-url", url},
      messages.size() - 2, got, output);
  EXPECT_EQ(code, 3) << output;
  std::vector<Message> expected(messages.begin(), messages.begin() + 299);
  expected.insert(expected.end(), messages.begin() + 301, messages.end());
  EXPECT_EQ(got, expected);
  EXPECT_NE(output.find("byte offset " + std::to_string(offsets[299])), std::string::npos)
      << output;
  EXPECT_NE(output.find(std::to_string(messages.size() - 2) + " events"), std::string::npos)
      << output;
}

// Messages that fail the wire checks: a log is evidence, so record keeps their bytes and
// replay publishes them as they are; both count them by reason.
TEST_F(CliTest, BadMessagesAreRecordedAndReplayedAsTheyCameAndCounted) {
  const std::string url = url_for(7707);
  auto messages = covtrack::testing::make_messages(40);
  Message zero_length = messages[0];  // a pose whose `device` string has length 0
  ASSERT_TRUE(zero_length.channel.starts_with("covtrack/pose/"));
  for (int i = 0; i < 4; ++i) zero_length.bytes[8 + 24 + i] = std::byte{0};
  Message wrong_type{"covtrack/status/sim", messages[0].bytes};  // a pose is no heartbeat
  messages.insert(messages.begin() + 10, zero_length);
  messages.insert(messages.begin() + 20, wrong_type);
  const fs::path log = dir_ / "with-bad.lcmlog";
  const std::string summary = record_with_cli(url, messages, log);
  EXPECT_EQ(covtrack::testing::read_log(log), messages);
  EXPECT_NE(summary.find("recorded as they came: 2 (bad length 1, wrong type 1)"), std::string::npos) << summary;

  std::vector<Message> got;
  std::string output;
  const int code = replay_and_collect(
      url, {COVTRACK_CLI, "replay", log.string(), "--speed", "0", "--lcm-url", url}, messages.size(), got, output);
  EXPECT_EQ(code, 0) << output;
  EXPECT_EQ(got, messages);
  EXPECT_NE(output.find("published as they are: 2 (bad length 1, wrong type 1)"), std::string::npos) << output;
}

TEST_F(CliTest, MissingLogIsAClearErrorWithExitCode1) {
  auto [code, out] = covtrack::testing::run(
      {COVTRACK_CLI, "replay", (dir_ / "missing.lcmlog").string(), "--lcm-url", url_for(7706)},
      dir_ / "missing.out");
  EXPECT_EQ(code, 1);
  EXPECT_NE(out.find("missing.lcmlog"), std::string::npos) << out;
  EXPECT_NE(out.find("No such file"), std::string::npos) << out;
}

}  // namespace
