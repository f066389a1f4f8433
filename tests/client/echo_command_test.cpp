// Over real multicast, inside the private network namespace this binary runs in
// (tests/netns_run.sh): the Subscriber on its own LCM instance, and `covtrack echo` as a
// separate process.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/channels.hpp"
#include "pose_messages.hpp"

using namespace covtrack;
using namespace std::chrono_literals;

namespace {

const std::string kUrl = "udpm://239.255.76.67:7711?ttl=0";
const std::string kCovtrack = COVTRACK_BINARY_DIR "/tools/covtrack/covtrack";

// Publishes dev/s every 5 ms from its own LCM instance, as a daemon would, until destroyed.
class Publisher {
 public:
  explicit Publisher(bool lost = false)
      : thread_([this, lost](std::stop_token stop) {
          lcm::LCM lcm(kUrl);
          for (std::int64_t seq = 0; !stop.stop_requested(); ++seq) {
            auto m = test::pose_message("dev", "s", seq);
            if (lost) m.status = pose_cov_t::STATUS_LOST;
            lcm.publish(pose_channel("dev", "s"), &m);
            std::this_thread::sleep_for(5ms);
          }
        }) {}

 private:
  std::jthread thread_;
};

struct ProcessOutput {
  std::vector<std::string> lines;
  int exit_code = -1;
};

ProcessOutput run(const std::string& command) {
  ProcessOutput out;
  FILE* p = popen(command.c_str(), "r");
  if (!p) return out;
  char buf[16384];
  while (fgets(buf, sizeof buf, p)) out.lines.emplace_back(buf);
  const int status = pclose(p);
  out.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

}  // namespace

TEST(SubscriberOverUdpm, ReceivesFromAnotherLcmInstance) {
  auto sub = client::Subscriber::open({.lcm_url = kUrl});
  ASSERT_TRUE(sub) << sub.error().message;
  {
    Publisher publisher;
    std::this_thread::sleep_for(300ms);
  }
  auto st = (*sub)->stream({"dev", "s"});
  ASSERT_TRUE(st);
  EXPECT_GT(st->counters.received, 20);
  EXPECT_EQ(st->counters.lost, 0);
  EXPECT_EQ(st->counters.rejected, 0);
}

TEST(EchoCommand, JsonLinesFromARealProcess) {
  Publisher publisher;
  const auto out = run(kCovtrack + " echo --json --count 5 --duration 10 --lcm-url '" + kUrl + "'");
  EXPECT_EQ(out.exit_code, 0);
  ASSERT_EQ(out.lines.size(), 5u);
  std::vector<nlohmann::json> lines;
  for (const auto& l : out.lines) lines.push_back(nlohmann::json::parse(l));
  for (std::size_t i = 1; i < lines.size(); ++i)
    EXPECT_EQ(lines[i]["sequence"].get<std::int64_t>(), lines[i - 1]["sequence"].get<std::int64_t>() + 1);
  const auto& j = lines[0];
  EXPECT_EQ(j["device"], "dev");
  EXPECT_EQ(j["sensor"], "s");
  EXPECT_EQ(j["parent_frame"], "world");
  EXPECT_EQ(j["child_frame"], "s");
  EXPECT_EQ(j["status"], "OK");
  EXPECT_EQ(j["covariance_convention"], "BODY");
  EXPECT_GE(j["receive_time_us"].get<std::int64_t>(), j["publish_time_us"].get<std::int64_t>());
  EXPECT_NEAR(j["position_m"][2].get<double>(), 3.0, 1e-12);
  EXPECT_EQ(j["orientation_wxyz"].size(), 4u);
  ASSERT_EQ(j["covariance"].size(), 36u);
  const Mat6 expected = test::test_covariance();
  for (int i = 0; i < 36; ++i)
    EXPECT_NEAR(j["covariance"][i].get<double>(), expected(i / 6, i % 6), 1e-18) << i;
}

TEST(EchoCommand, JsonOfALostStreamHasNoCovariance) {
  Publisher publisher(/*lost=*/true);
  const auto out = run(kCovtrack + " echo --json --count 1 --duration 10 --lcm-url '" + kUrl + "'");
  ASSERT_EQ(out.lines.size(), 1u);
  const auto j = nlohmann::json::parse(out.lines[0]);
  EXPECT_EQ(j["status"], "LOST");
  EXPECT_TRUE(j["covariance"].is_null());
}

TEST(EchoCommand, PlainTableOncePerSecondWhenNotATerminal) {
  Publisher publisher;
  const auto out = run(kCovtrack + " echo 'dev/.*' --duration 2.5 --lcm-url '" + kUrl + "'");
  EXPECT_EQ(out.exit_code, 0);
  int headers = 0, rows = 0;
  for (const auto& l : out.lines) {
    EXPECT_EQ(l.find('\x1b'), std::string::npos) << "no terminal escapes into a pipe";
    if (l.starts_with("stream")) ++headers;
    if (l.starts_with("dev/s ")) ++rows;
  }
  EXPECT_GE(headers, 2);
  EXPECT_LE(headers, 3);
  EXPECT_GE(rows, 1);
}

namespace {

// Poses and heartbeats of device "hb" (period 50 ms) for `seconds`, then silence: a daemon killed.
void publish_then_die(double seconds) {
  lcm::LCM lcm(kUrl);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (std::int64_t seq = 0; std::chrono::steady_clock::now() < end; ++seq) {
    const auto m = test::pose_message("hb", "s", seq);
    lcm.publish(pose_channel("hb", "s"), &m);
    device_status_t st{};
    st.device = "hb";
    st.heartbeat_period_us = 50'000;
    st.instance_id = 77;
    lcm.publish(status_channel("hb"), &st);
    std::this_thread::sleep_for(10ms);
  }
}

}  // namespace

TEST(EchoCommand, DeviceWhoseHeartbeatStopsIsUnreachableAndItsStreamLost) {
  std::jthread daemon([] { publish_then_die(0.5); });
  const auto json = run(kCovtrack + " echo --json --duration 2 --lcm-url '" + kUrl + "'");
  ASSERT_FALSE(json.lines.empty());
  const auto last = nlohmann::json::parse(json.lines.back());
  EXPECT_EQ(last["status"], "LOST");
  EXPECT_EQ(last["device_unreachable"], true);
  EXPECT_EQ(nlohmann::json::parse(json.lines.front())["device_unreachable"], false);
  daemon.join();

  std::jthread again([] { publish_then_die(0.5); });
  const auto table = run(kCovtrack + " echo --duration 2.2 --lcm-url '" + kUrl + "'");
  ASSERT_GE(table.lines.size(), 2u);
  std::string last_table;  // the lines after the last header
  for (const auto& l : table.lines) last_table = l.starts_with("stream") ? l : last_table + l;
  EXPECT_NE(last_table.find("UNREACHABLE: no heartbeat for"), std::string::npos) << last_table;
  EXPECT_NE(last_table.find("LOST"), std::string::npos) << last_table;
}

TEST(EchoCommand, SaysSoWhenNothingArrives) {
  const auto out = run(kCovtrack + " echo --duration 3.5 --lcm-url '" + kUrl + "' 2>&1 >/dev/null");
  EXPECT_EQ(out.exit_code, 0);
  std::string all;
  for (const auto& l : out.lines) all += l;
  EXPECT_NE(all.find("nothing received for 3 s on " + kUrl), std::string::npos) << all;
}

TEST(EchoCommand, BadUrlFailsAtOnceWithAMessage) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto out = run(kCovtrack + " echo --lcm-url udpm://10.1.2.3:7667 2>&1");
  EXPECT_NE(out.exit_code, 0);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 3s);
  ASSERT_FALSE(out.lines.empty());
  EXPECT_NE(out.lines[0].find("multicast"), std::string::npos);
}

TEST(EchoCommand, SigintEndsItCleanly) {
  const std::string url = "--lcm-url=" + kUrl;
  const char* argv[] = {kCovtrack.c_str(), "echo", "--json", url.c_str(), nullptr};
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, kCovtrack.c_str(), nullptr, nullptr, const_cast<char**>(argv), environ), 0);
  std::this_thread::sleep_for(300ms);  // idle: no publisher
  ::kill(pid, SIGINT);
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 500ms);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0);
}
