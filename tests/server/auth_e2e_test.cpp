// Authenticated poses end to end, over real multicast in this test's network namespace:
// covtrackd signs with a key file; a Subscriber with the key receives its streams, and
// refuses and counts messages injected from another process's LCM instance: forged (an
// altered byte, another key), unauthenticated (no trailer, a cut trailer) and replayed
// (captured messages sent again; a validly signed message of a sender instance never
// heard, sent long ago). A Subscriber without the key receives the same streams as
// before, and `covtrack echo --key-file` reports the same counts.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/message_auth.hpp"
#include "client/pose_messages.hpp"
#include "daemon_process.hpp"
#include "support/wait_for.hpp"

using namespace covtrack;
using namespace std::chrono_literals;

namespace {

const std::string kUrl = "udpm://239.255.76.67:7721?ttl=0";
const std::string kChannel = "covtrack/pose/optical/head";
const std::string kCovtrack = COVTRACK_BINARY_DIR "/tools/covtrack/covtrack";

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "/auth_e2e_" + std::to_string(::getpid()) + "_" + name;
}

std::string new_key_file(const std::string& name) {
  const std::string path = temp_path(name);
  ::unlink(path.c_str());
  EXPECT_TRUE(write_new_auth_key(path));
  return path;
}

std::string config(const std::string& key_file) {
  return "[auth]\nkey_file = \"" + key_file + "\"\n\n"
         "[devices.optical]\ntype = \"sim\"\nsensors = [\"head\"]\nrate_hz = 200\nseed = 3\n"
         "sigma_m = [0.001, 0.001, 0.001]\nsigma_rad = [0.002, 0.002, 0.002]\n";
}

using covtrack::testing::wait_for;

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Keeps the bytes of every pose message the daemon sends on kChannel, as a listener on the
// network could.
class Capture {
 public:
  Capture() : lcm_(kUrl) { lcm_.subscribe(kChannel, &Capture::on_message, this); }
  // Handles messages until `count` are kept or the deadline passes; the kept ones.
  std::vector<std::vector<std::uint8_t>> take(std::size_t count) {
    const auto end = std::chrono::steady_clock::now() + 20s;
    while (captured_.size() < count && std::chrono::steady_clock::now() < end) lcm_.handleTimeout(20);
    return captured_;
  }

 private:
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    const auto* data = static_cast<const std::uint8_t*>(rbuf->data);
    captured_.emplace_back(data, data + rbuf->data_size);
  }
  lcm::LCM lcm_;
  std::vector<std::vector<std::uint8_t>> captured_;
};

std::vector<std::uint8_t> plain_pose(std::int64_t sequence) {
  return test::encoded(test::pose_message("optical", "head", sequence));
}

}  // namespace

TEST(AuthenticatedPoses, ForgedUnauthenticatedAndReplayedMessagesAreRefusedAndCounted) {
  const std::string key_file = new_key_file("key");
  const auto key = load_auth_key(key_file);
  ASSERT_TRUE(key) << key.error().message;
  const auto other_key = load_auth_key(new_key_file("other"));
  ASSERT_TRUE(other_key);

  auto keyed = client::Subscriber::open({.lcm_url = kUrl, .key_file = key_file});
  ASSERT_TRUE(keyed) << keyed.error().message;
  auto plain = client::Subscriber::open({.lcm_url = kUrl});
  ASSERT_TRUE(plain) << plain.error().message;
  ASSERT_FALSE((*plain)->authentication());
  Capture capture;
  const std::string echo_log = temp_path("echo.log");
  test::DaemonProcess echo(kCovtrack, {"echo", "--lcm-url", kUrl, "--key-file", key_file}, echo_log);
  ASSERT_TRUE(wait_for([&] { return read_file(echo_log).find("listening on") != std::string::npos; }))
      << read_file(echo_log);

  test::DaemonProcess daemon(config(key_file), kUrl);
  const auto captured = capture.take(5);
  ASSERT_EQ(captured.size(), 5u);
  const StreamId head{"optical", "head"};
  auto received = [](client::Subscriber& s, const StreamId& id) {
    const auto st = s.stream(id);
    return st ? st->counters.received : 0;
  };
  ASSERT_TRUE(wait_for([&] { return received(**keyed, head) >= 50 && received(**plain, head) >= 50; }));
  // The daemon's own messages: all authentic, and read without the key as before.
  EXPECT_EQ((*keyed)->rejections().total, 0) << (*keyed)->rejections().summary();
  EXPECT_EQ((*plain)->rejections().total, 0) << (*plain)->rejections().summary();

  lcm::LCM injector(kUrl);
  auto inject = [&](const std::vector<std::uint8_t>& bytes) {
    ASSERT_EQ(injector.publish(kChannel, bytes.data(), static_cast<unsigned>(bytes.size())), 0);
  };
  // Forged: one altered byte of a captured pose (in its covariance); a pose signed with another key.
  auto altered = captured[1];
  altered[altered.size() - kAuthTrailerBytes - 8] ^= 0x40;
  inject(altered);
  auto other = plain_pose(1'000'000);
  append_auth_trailer(*other_key, kChannel, {42, 1, now_us()}, other);
  inject(other);
  // Unauthenticated: a valid pose without a trailer; a captured one cut inside its trailer.
  inject(plain_pose(2'000'000));
  inject(std::vector<std::uint8_t>(captured[2].begin(), captured[2].end() - 10));
  // Replayed: the captured messages again; and a message of a sender instance this client
  // never heard from, validly signed but sent 10 s ago (captured from an earlier daemon).
  for (const auto& message : captured) inject(message);
  auto old = plain_pose(3'000'000);
  append_auth_trailer(*key, kChannel, {7, 1, now_us() - 10'000'000}, old);
  inject(old);

  auto counts = [&] { return (*keyed)->authentication().value_or(client::AuthCounters{}); };
  ASSERT_TRUE(wait_for([&] {
    const auto c = counts();
    return c.forged >= 2 && c.unauthenticated >= 2 && c.replayed >= 6;
  })) << (*keyed)->rejections().summary();
  const auto c = counts();
  EXPECT_EQ(c.forged, 2);
  EXPECT_EQ(c.unauthenticated, 2);
  EXPECT_EQ(c.replayed, 6);
  EXPECT_GE(c.authenticated, 50);
  const auto by_reason = (*keyed)->rejections().by_reason;
  EXPECT_EQ(by_reason.at("forged"), 2);
  EXPECT_EQ(by_reason.at("unauthenticated"), 2);
  EXPECT_EQ(by_reason.at("replayed"), 6);
  // None of them reached the stream: not received, not rejected there, not foreign.
  const auto st = (*keyed)->stream(head);
  ASSERT_TRUE(st);
  EXPECT_EQ(st->counters.rejected, 0);
  EXPECT_EQ(st->counters.foreign, 0);
  EXPECT_EQ(st->counters.lost, 0);
  // Without the key, only the cut trailer fails the wire checks (bytes after the last field).
  const auto plain_rejections = (*plain)->rejections();
  EXPECT_EQ(plain_rejections.by_reason.size(), 1u) << plain_rejections.summary();
  EXPECT_EQ(plain_rejections.by_reason.count("trailing bytes"), 1u) << plain_rejections.summary();

  // The daemon keeps being received after the injections.
  const auto before = received(**keyed, head);
  EXPECT_TRUE(wait_for([&] { return received(**keyed, head) >= before + 20; }));

  int status = -1;
  ASSERT_GE(echo.stop(SIGINT, status), 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  const std::string out = read_file(echo_log);
  EXPECT_NE(out.find("authenticated messages only (key " + key_file + ")"), std::string::npos) << out;
  EXPECT_NE(out.find("refused 2 unauthenticated, 2 forged, 6 replayed"), std::string::npos) << out;
}

TEST(AuthenticatedPoses, ASubscriberRefusesAKeyFileOthersCanRead) {
  const std::string key_file = new_key_file("readable");
  ::chmod(key_file.c_str(), 0644);
  auto sub = client::Subscriber::open({.lcm_url = kUrl, .key_file = key_file});
  ASSERT_FALSE(sub);
  EXPECT_NE(sub.error().message.find("others may read"), std::string::npos) << sub.error().message;
}
