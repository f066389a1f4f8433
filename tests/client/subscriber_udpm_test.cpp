// The Subscriber's own udpm path (no lcm::LCM receiving), against lcm::LCM publishers over
// multicast inside the private network namespace this binary runs in (tests/netns_run.sh):
// a pose larger than one datagram, a datagram that is not LCM's, and no loss in a burst
// the default receive buffer is sized for (counted, not timed).
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/channels.hpp"
#include "pose_messages.hpp"
#include "raw_datagram.hpp"

using namespace covtrack;
using namespace std::chrono_literals;

namespace {

std::string url(int port) { return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0"; }

// Waits until `pred` holds, up to 20 s.
template <typename P>
bool eventually(P pred) {
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!pred() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(5ms);
  return pred();
}

std::unique_ptr<client::Subscriber> open(const std::string& u, const std::string& pattern = ".*") {
  auto sub = client::Subscriber::open({.lcm_url = u, .pattern = pattern});
  EXPECT_TRUE(sub) << sub.error().message;
  return sub ? std::move(*sub) : nullptr;
}

}  // namespace

TEST(SubscriberUdpm, ReportsItsReceiveBufferOnUdpmOnly) {
  auto sub = open(url(7770));
  ASSERT_TRUE(sub);
  ASSERT_TRUE(sub->receive_buffer());
  EXPECT_EQ(sub->receive_buffer()->requested, 4 << 20);
  auto memq = open("memq://");
  ASSERT_TRUE(memq);
  EXPECT_FALSE(memq->receive_buffer());
}

// LCM sends a message of more than 65,499 bytes as fragments: one with a 70 kB frame name.
TEST(SubscriberUdpm, APoseInFragmentsIsReassembledAndChecked) {
  auto sub = open(url(7771), "big/.*");
  ASSERT_TRUE(sub);
  lcm::LCM lcm(url(7771));
  auto m = test::pose_message("big", "s", 0);
  m.parent_frame = std::string(70'000, 'w');
  ASSERT_GT(m.getEncodedSize(), 65'536);
  lcm.publish(pose_channel("big", "s"), &m);
  auto small = test::pose_message("big", "s", 1);
  lcm.publish(pose_channel("big", "s"), &small);
  ASSERT_TRUE(eventually([&] {
    auto s = sub->stream({"big", "s"});
    return s && s->counters.received + s->counters.rejected == 2;
  }));
  const auto counters = sub->stream({"big", "s"})->counters;
  EXPECT_EQ(counters.lost, 0);  // sequence 0 arrived (accepted or refused), then 1
  EXPECT_EQ(counters.received, 2) << sub->rejections().summary();
}

TEST(SubscriberUdpm, ADatagramThatIsNotLcmsIsCountedAsRejected) {
  auto sub = open(url(7772));
  ASSERT_TRUE(sub);
  const char fragment_without_count[] = "LC03\0\0\0\1\0\0\0\x10\0\0\0\0\0\0\0\0chan";  // fragment 0 of 0
  ASSERT_TRUE(test::send_datagram("239.255.76.67", 7772, fragment_without_count, sizeof fragment_without_count));
  ASSERT_TRUE(eventually([&] { return sub->rejections().total == 1; }));
  EXPECT_EQ(sub->rejections().by_reason.count("bad fragment number"), 1u) << sub->rejections().summary();
}

// The default receive buffer is sized to hold 0.1 s of a 50 kHz aggregate (about 6,500
// pose datagrams): a burst of 5,000 sent back to back arrives whole even if the reading
// thread never ran meanwhile. (Sustained rates depend on the CPU the machine can spare:
// bench_client_latency measures them.) LCM's default buffer holds about 330.
TEST(SubscriberUdpm, TheDefaultBufferHoldsABurstOfFiveThousandPoses) {
  auto sub = open(url(7773), "burst/.*");
  ASSERT_TRUE(sub);
  if (!sub->receive_buffer()->note.empty()) GTEST_SKIP() << sub->receive_buffer()->note;
  constexpr int kStreams = 10, kSent = 5000;
  {
    lcm::LCM lcm(url(7773));
    std::vector<pose_cov_t> messages;
    for (int s = 0; s < kStreams; ++s) messages.push_back(test::pose_message("burst", "s" + std::to_string(s), 0));
    for (int i = 0; i < kSent; ++i) {
      auto& m = messages[static_cast<std::size_t>(i % kStreams)];
      lcm.publish(pose_channel(m.device, m.sensor), &m);
      ++m.sequence;
    }
  }
  const auto total = [&](auto field) {
    std::int64_t n = 0;
    for (const auto& s : sub->streams()) n += s.counters.*field;
    return n;
  };
  EXPECT_TRUE(eventually([&] { return total(&client::StreamCounters::received) == kSent; }))
      << "received " << total(&client::StreamCounters::received) << " of " << kSent;
  EXPECT_EQ(total(&client::StreamCounters::lost), 0);
  EXPECT_EQ(sub->streams().size(), static_cast<std::size_t>(kStreams));
}
