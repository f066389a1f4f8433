// The udpm receiver against real LCM senders over multicast, inside the private network
// namespace this binary runs in (tests/netns_run.sh): short and fragmented messages as
// lcm::LCM sends them, a datagram that is not LCM's, another group on the same port, and
// the URL's options.
#include <gtest/gtest.h>
#include <poll.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "raw_datagram.hpp"
#include "udpm_receiver.hpp"  // client/streams/src: the receiver is internal to the Subscriber

using namespace covtrack;
using namespace std::chrono_literals;
using Bytes = std::vector<std::byte>;

namespace {

std::string url(int port, const char* group = "239.255.76.67") {
  return "udpm://" + std::string(group) + ":" + std::to_string(port) + "?ttl=0";
}

Bytes random_bytes(std::size_t n, unsigned seed) {
  Bytes b(n);
  std::mt19937 rng(seed);
  for (auto& x : b) x = std::byte(rng());
  return b;
}

struct Collector final : client::UdpmReceiver::Handler {
  std::string prefix;  // the channels wanted
  std::vector<std::pair<std::string, Bytes>> messages;
  std::vector<std::pair<std::string, lcm_wire::DatagramRejection>> malformed;

  bool wants(std::string_view channel) override { return channel.starts_with(prefix); }
  void on_message(std::string_view channel, std::span<const std::byte> payload) override {
    messages.emplace_back(std::string(channel), Bytes(payload.begin(), payload.end()));
  }
  void on_malformed(const std::string& from, const lcm_wire::DatagramRejection& why) override {
    malformed.emplace_back(from, why);
  }
};

// Reads until `done` holds, waiting on the socket; false after 10 s without it.
bool read_until(client::UdpmReceiver& r, Collector& c, const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    pollfd p{r.fd(), POLLIN, 0};
    if (::poll(&p, 1, 100) > 0) r.read_available(c, 16);
  }
  return true;
}

std::unique_ptr<client::UdpmReceiver> open_receiver(const std::string& u) {
  auto r = client::UdpmReceiver::open(u);
  EXPECT_TRUE(r) << r.error().message;
  return r ? std::move(*r) : nullptr;
}

long rmem_max() {
  long v = -1;
  std::ifstream("/proc/sys/net/core/rmem_max") >> v;
  return v;
}

}  // namespace

TEST(UdpmReceiver, ShortMessagesFromLcmArriveInOrderAndUnwantedChannelsDoNot) {
  auto r = open_receiver(url(7760));
  ASSERT_TRUE(r);
  lcm::LCM lcm(url(7760));
  ASSERT_TRUE(lcm.good());
  Collector c;
  c.prefix = "rx/";
  constexpr int kCount = 500;
  for (int i = 0; i < kCount; ++i) {
    const Bytes payload = random_bytes(static_cast<std::size_t>(i % 700), static_cast<unsigned>(i));
    lcm.publish("rx/short", payload.data(), static_cast<unsigned>(payload.size()));
    lcm.publish("elsewhere", payload.data(), static_cast<unsigned>(payload.size()));
  }
  ASSERT_TRUE(read_until(*r, c, [&] { return c.messages.size() >= kCount; })) << c.messages.size();
  for (int i = 0; i < kCount; ++i) {
    EXPECT_EQ(c.messages[i].first, "rx/short");
    EXPECT_EQ(c.messages[i].second, random_bytes(static_cast<std::size_t>(i % 700), static_cast<unsigned>(i)))
        << "message " << i;
  }
  EXPECT_TRUE(c.malformed.empty());
}

// LCM 1.3 sends a payload and channel of up to 65,499 bytes as one datagram, larger ones
// as fragments of 65,487 bytes.
TEST(UdpmReceiver, FragmentedMessagesFromLcmAreReassembled) {
  auto r = open_receiver(url(7761));
  ASSERT_TRUE(r);
  lcm::LCM lcm(url(7761));
  Collector c;
  c.prefix = "rx/";
  const std::vector<std::size_t> sizes = {65'000, 65'536 + 1, 200'000, 1'000'000};
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    const Bytes payload = random_bytes(sizes[i], static_cast<unsigned>(i));
    lcm.publish("rx/big", payload.data(), static_cast<unsigned>(payload.size()));
    lcm.publish("unwanted/big", payload.data(), static_cast<unsigned>(payload.size()));
  }
  ASSERT_TRUE(read_until(*r, c, [&] { return c.messages.size() >= sizes.size(); })) << c.messages.size();
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    EXPECT_EQ(c.messages[i].first, "rx/big");
    EXPECT_EQ(c.messages[i].second, random_bytes(sizes[i], static_cast<unsigned>(i))) << sizes[i] << " bytes";
  }
  EXPECT_TRUE(c.malformed.empty());
  EXPECT_EQ(r->abandoned(), 0);
}

TEST(UdpmReceiver, ADatagramThatIsNotLcmsIsReportedAndReceivingGoesOn) {
  auto r = open_receiver(url(7762));
  ASSERT_TRUE(r);
  const char junk[] = "NOT-LCM at all";
  ASSERT_TRUE(test::send_datagram("239.255.76.67", 7762, junk, sizeof junk));
  lcm::LCM lcm(url(7762));
  const Bytes payload = random_bytes(100, 1);
  lcm.publish("rx/after", payload.data(), static_cast<unsigned>(payload.size()));
  Collector c;
  c.prefix = "rx/";
  ASSERT_TRUE(read_until(*r, c, [&] { return !c.messages.empty(); }));
  ASSERT_EQ(c.malformed.size(), 1u);
  EXPECT_EQ(c.malformed[0].second.fault, lcm_wire::DatagramFault::BadMagic);
  EXPECT_NE(c.malformed[0].first.find(':'), std::string::npos) << c.malformed[0].first;  // address:port
  EXPECT_EQ(c.messages[0].second, payload);
}

// With LCM, every instance on a port receives what is sent to any group joined on the
// host at that port; this receiver only what is sent to its own group.
TEST(UdpmReceiver, AnotherGroupOnTheSamePortIsNotReceived) {
  auto r = open_receiver(url(7763));
  ASSERT_TRUE(r);
  lcm::LCM other(url(7763, "239.255.76.68"));  // joins 239.255.76.68 on this host
  lcm::LCM mine(url(7763));
  const Bytes payload = random_bytes(100, 1);
  other.publish("rx/other-group", payload.data(), static_cast<unsigned>(payload.size()));
  mine.publish("rx/my-group", payload.data(), static_cast<unsigned>(payload.size()));
  Collector c;
  c.prefix = "rx/";
  ASSERT_TRUE(read_until(*r, c, [&] { return !c.messages.empty(); }));
  r->read_available(c, 16);
  ASSERT_EQ(c.messages.size(), 1u);
  EXPECT_EQ(c.messages[0].first, "rx/my-group");
}

TEST(UdpmReceiver, TheUrlSetsTheReceiveBufferAndACapIsReported) {
  const long cap = rmem_max();
  ASSERT_GT(cap, 4096);
  auto fits = open_receiver(url(7764) + "&recv_buf_size=" + std::to_string(cap / 2));
  ASSERT_TRUE(fits);
  EXPECT_EQ(fits->receive_buffer().requested, cap / 2);
  EXPECT_EQ(fits->receive_buffer().granted, 2 * (cap / 2));  // Linux counts double
  EXPECT_EQ(fits->receive_buffer().note, "");
  auto capped = open_receiver(url(7764) + "&recv_buf_size=" + std::to_string(cap + 4096));
  ASSERT_TRUE(capped);
  EXPECT_EQ(capped->receive_buffer().granted, 2 * cap);
  EXPECT_NE(capped->receive_buffer().note.find("net.core.rmem_max (" + std::to_string(cap) + ")"),
            std::string::npos)
      << capped->receive_buffer().note;
  auto by_default = open_receiver(url(7764));
  ASSERT_TRUE(by_default);
  EXPECT_EQ(by_default->receive_buffer().requested, client::UdpmReceiver::kDefaultReceiveBufferBytes);
}

TEST(UdpmReceiver, ABadUrlOptionIsAnErrorNamingIt) {
  for (const auto& [option, named] : std::vector<std::pair<std::string, std::string>>{
           {"ttl=300", "ttl='300'"}, {"recv_buf_size=-1", "recv_buf_size='-1'"},
           {"recv_buf_size=big", "recv_buf_size='big'"}, {"colour=red", "unknown option 'colour'"}}) {
    auto r = client::UdpmReceiver::open("udpm://239.255.76.67:7765?" + option);
    ASSERT_FALSE(r) << option;
    EXPECT_NE(r.error().message.find(named), std::string::npos) << r.error().message;
  }
  EXPECT_TRUE(client::UdpmReceiver::open("udpm://239.255.76.67:7765?ttl=1&transmit_only=true"));
  EXPECT_TRUE(client::UdpmReceiver::open("udpm://239.255.76.67:7765?ttl=0x01&recv_buf_size=0x10000"));
}
