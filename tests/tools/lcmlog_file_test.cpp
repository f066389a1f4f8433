// Log files written by LogWriter read back by LogReader, and damaged logs: the reader must
// deliver every intact event and name the offset where the damage starts.
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "covtrack/lcmlog/channel_filter.hpp"
#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/lcmlog/log_writer.hpp"
#include "test_support.hpp"

namespace {
using namespace covtrack::lcmlog;
using covtrack::testing::Message;

class LogFileTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = covtrack::testing::make_temp_dir(); }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Writes `messages` one millisecond apart; returns the offset of each event.
  std::vector<std::uint64_t> write_log(const std::filesystem::path& path,
                                       const std::vector<Message>& messages) {
    auto writer = LogWriter::create(path.string(), false);
    EXPECT_TRUE(writer.has_value()) << writer.error().message;
    std::vector<std::uint64_t> offsets;
    std::uint64_t at = 0;
    for (std::size_t i = 0; i < messages.size(); ++i) {
      offsets.push_back(at);
      EXPECT_TRUE(writer->write(1'000'000 + static_cast<std::int64_t>(i) * 1000,
                                messages[i].channel, messages[i].bytes));
      at += kEventHeaderBytes + messages[i].channel.size() + messages[i].bytes.size();
    }
    return offsets;
  }

  std::filesystem::path dir_;
};

TEST_F(LogFileTest, WrittenEventsReadBackIdenticalAndFlushedAtOnce) {
  const auto messages = covtrack::testing::make_messages(500);
  const auto path = dir_ / "a.lcmlog";
  auto writer = LogWriter::create(path.string(), false);
  ASSERT_TRUE(writer) << writer.error().message;
  ASSERT_TRUE(writer->write(42, messages[0].channel, messages[0].bytes));
  // Still open: the event must already be on disk (flush per event).
  EXPECT_EQ(covtrack::testing::read_log(path), std::vector<Message>{messages[0]});
  for (std::size_t i = 1; i < messages.size(); ++i)
    ASSERT_TRUE(writer->write(42 + static_cast<std::int64_t>(i), messages[i].channel,
                              messages[i].bytes));
  auto reader = LogReader::open(path.string());
  ASSERT_TRUE(reader) << reader.error().message;
  std::size_t i = 0;
  while (auto e = reader->next()) {
    ASSERT_LT(i, messages.size());
    EXPECT_EQ(e->timestamp_us, 42 + static_cast<std::int64_t>(i));
    EXPECT_EQ(e->event_number, static_cast<std::int64_t>(i));
    EXPECT_EQ(e->channel, messages[i].channel);
    EXPECT_TRUE(std::ranges::equal(e->payload, messages[i].bytes));
    ++i;
  }
  EXPECT_EQ(i, messages.size());
  EXPECT_TRUE(reader->damage().empty());
}

TEST_F(LogFileTest, RefusesToOverwriteUnlessForced) {
  const auto path = dir_ / "exists.lcmlog";
  std::ofstream(path) << "keep me";
  auto refused = LogWriter::create(path.string(), false);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("--force"), std::string::npos);
  EXPECT_EQ(covtrack::testing::read_file(path), "keep me");
  EXPECT_TRUE(LogWriter::create(path.string(), true));
  EXPECT_EQ(std::filesystem::file_size(path), 0u);
}

TEST_F(LogFileTest, MissingFileIsAClearError) {
  auto reader = LogReader::open((dir_ / "nope.lcmlog").string());
  ASSERT_FALSE(reader);
  EXPECT_NE(reader.error().message.find("No such file"), std::string::npos);
}

TEST_F(LogFileTest, AFifoIsRefusedWithoutWaitingForAWriter) {
  const auto fifo = dir_ / "session.lcm";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto reader = LogReader::open(fifo.string());  // blocked here before O_NONBLOCK
  ASSERT_FALSE(reader);
  EXPECT_NE(reader.error().message.find("not a regular file"), std::string::npos) << reader.error().message;
}

TEST_F(LogFileTest, TruncatedMidEventReadsAllCompleteEvents) {
  const auto messages = covtrack::testing::make_messages(100);
  const auto path = dir_ / "cut.lcmlog";
  const auto offsets = write_log(path, messages);
  const std::uint64_t cut_at = offsets[60] + 40;  // inside event 60's channel/payload
  std::filesystem::resize_file(path, cut_at);

  auto reader = LogReader::open(path.string());
  ASSERT_TRUE(reader);
  std::vector<Message> got;
  while (auto e = reader->next())
    got.push_back({std::string(e->channel), {e->payload.begin(), e->payload.end()}});
  EXPECT_EQ(got, std::vector<Message>(messages.begin(), messages.begin() + 60));
  ASSERT_EQ(reader->damage().size(), 1u);
  EXPECT_EQ(reader->damage()[0].offset, offsets[60]);
  EXPECT_EQ(reader->damage()[0].skipped_bytes, 40u);
  EXPECT_TRUE(reader->damage()[0].truncated);
}

TEST_F(LogFileTest, TruncatedInsideNextSyncWordKeepsTheLastCompleteEvent) {
  const auto messages = covtrack::testing::make_messages(10);
  const auto path = dir_ / "cut-sync.lcmlog";
  const auto offsets = write_log(path, messages);
  std::filesystem::resize_file(path, offsets[9] + 2);
  auto reader = LogReader::open(path.string());
  ASSERT_TRUE(reader);
  std::size_t n = 0;
  while (reader->next()) ++n;
  EXPECT_EQ(n, 9u);
  ASSERT_EQ(reader->damage().size(), 1u);
  EXPECT_EQ(reader->damage()[0].offset, offsets[9]);
}

TEST_F(LogFileTest, GarbageOverAnEventBoundaryLosesOnlyTheTwoTouchedEvents) {
  const auto messages = covtrack::testing::make_messages(100);
  const auto path = dir_ / "garbage.lcmlog";
  const auto offsets = write_log(path, messages);
  {
    // 64 bytes from the end of event 40's payload over event 41's header.
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(offsets[41] - 20));
    for (int i = 0; i < 64; ++i) f.put(static_cast<char>(0x5A + i));
  }
  auto reader = LogReader::open(path.string());
  ASSERT_TRUE(reader);
  std::vector<Message> got;
  while (auto e = reader->next())
    got.push_back({std::string(e->channel), {e->payload.begin(), e->payload.end()}});
  std::vector<Message> expected(messages.begin(), messages.begin() + 40);
  expected.insert(expected.end(), messages.begin() + 42, messages.end());
  EXPECT_EQ(got, expected);
  ASSERT_EQ(reader->damage().size(), 1u);
  EXPECT_EQ(reader->damage()[0].offset, offsets[40]);
  EXPECT_EQ(reader->damage()[0].skipped_bytes, offsets[42] - offsets[40]);
  EXPECT_FALSE(reader->damage()[0].truncated);
}

TEST_F(LogFileTest, CorruptedLengthFieldDoesNotSwallowFollowingEvents) {
  const auto messages = covtrack::testing::make_messages(50);
  const auto path = dir_ / "length.lcmlog";
  const auto offsets = write_log(path, messages);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(offsets[10] + 24));  // event 10's data length
    const char big[4] = {0, 0, 0x10, 0};                     // 4096: lands inside the file
    f.write(big, 4);
  }
  auto reader = LogReader::open(path.string());
  ASSERT_TRUE(reader);
  std::size_t n = 0;
  while (reader->next()) ++n;
  EXPECT_EQ(n, 49u);
  ASSERT_EQ(reader->damage().size(), 1u);
  EXPECT_EQ(reader->damage()[0].offset, offsets[10]);
  EXPECT_EQ(reader->damage()[0].skipped_bytes, offsets[11] - offsets[10]);
}

TEST(ChannelFilterTest, MatchesWholeNamesLikeLcm) {
  auto filter = ChannelFilter::create("covtrack/pose/.*");
  ASSERT_TRUE(filter);
  EXPECT_TRUE(filter->matches("covtrack/pose/sim/head"));
  EXPECT_TRUE(filter->matches("covtrack/pose/sim/head"));  // cached verdict
  EXPECT_FALSE(filter->matches("covtrack/raw/fastrak"));
  EXPECT_FALSE(filter->matches("x/covtrack/pose/sim/head"));
  auto partial = ChannelFilter::create("pose");
  ASSERT_TRUE(partial);
  EXPECT_FALSE(partial->matches("covtrack/pose/sim/head"));
}

TEST(ChannelFilterTest, InvalidRegexIsAnErrorNamingIt) {
  auto filter = ChannelFilter::create("covtrack/(pose");
  ASSERT_FALSE(filter);
  EXPECT_NE(filter.error().message.find("pattern 'covtrack/(pose' is not a POSIX extended"), std::string::npos)
      << filter.error().message;
}

TEST(ChannelFilterTest, SpeaksTheSubscribersDialect) {
  // POSIX extended, as `covtrack echo` and LCM: alternation and classes, no Perl extras.
  auto filter = ChannelFilter::create("covtrack/(pose|truth)/[a-z]+/head");
  ASSERT_TRUE(filter);
  EXPECT_TRUE(filter->matches("covtrack/truth/sim/head"));
  EXPECT_FALSE(filter->matches("covtrack/raw/sim/head"));
  EXPECT_FALSE(ChannelFilter::create("covtrack/(?=pose).*"));  // a lookahead is ECMAScript's
}

}  // namespace
