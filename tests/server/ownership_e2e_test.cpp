// One publisher per device, end to end: covtrackd processes with the same config inside
// this test's network namespace (tests/netns_run.sh), a client-library Subscriber and a
// listener that records who sends each heartbeat.
//
// - A second daemon does not start a device the first publishes, says who holds it, and
//   exits (every device refused); the client hears one publisher; once the first is
//   killed, a new daemon takes the device.
// - Two daemons started at once: exactly one keeps the device.
// - Without a claim wait both start; the later claim gives the device up when the two
//   hear each other's heartbeats.
// - --allow-duplicate-publishers: both publish, both daemons say so, and the client names
//   both ("device rig published by two daemons: host/pid and host/pid"), covtrack echo as well.
#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>

#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/channel_messages.hpp"
#include "covtrack/protocol/clock.hpp"
#include "daemon_process.hpp"

using namespace covtrack;
using namespace std::chrono_literals;

namespace {

std::string url_for(int port) { return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0"; }

// Heartbeats at 10 Hz: a client forgets a silent publisher after 0.3 s.
std::string config_text(const std::string& daemon_extra = "") {
  return "[daemon]\nheartbeat_hz = 10\n" + daemon_extra +
         "[devices.rig]\ntype = \"sim\"\nsensor_count = 1\nrate_hz = 200\n"
         "sigma_m = [0.001, 0.002, 0.001]\nsigma_rad = [0.004, 0.002, 0.003]\n";
}

std::string write_config(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/covtrack_ownership_" + name + "_" + std::to_string(::getpid()) + ".toml";
  std::ofstream(path) << text;
  return path;
}

std::string read_file(const std::string& path) {
  std::stringstream s;
  s << std::ifstream(path).rdbuf();
  return s.str();
}

std::string host_name() {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  return host;
}

// A daemon whose output (its log) goes to a file.
struct Daemon {
  Daemon(const std::string& name, const std::string& config, const std::string& url,
         std::vector<std::string> extra = {})
      : log(::testing::TempDir() + "/covtrack_ownership_" + name + "_" + std::to_string(::getpid()) + ".log") {
    std::vector<std::string> args{"--config", config, "--lcm-url", url, "--log-level", "warn"};
    args.insert(args.end(), extra.begin(), extra.end());
    process.emplace(args, log);
  }
  pid_t pid() const { return process->pid(); }
  std::string output() const { return read_file(log); }
  std::string log;
  std::optional<test::DaemonProcess> process;
};

// Who sends the heartbeats of device "rig", in order of arrival.
class HeartbeatLog {
 public:
  explicit HeartbeatLog(const std::string& url) : lcm_(url) {
    // Heartbeats wait here while the test waits for a process; LCM's default queue holds 30.
    lcm_.subscribe("covtrack/status/rig", &HeartbeatLog::on_status, this)->setQueueCapacity(100000);
  }
  bool good() { return lcm_.good(); }
  // Handles heartbeats until `done` holds for those heard so far, or `seconds` passed.
  bool until(const std::function<bool(const std::vector<device_status_t>&)>& done, double seconds = 20) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    pollfd pfd{lcm_.getFileno(), POLLIN, 0};
    while (!done(heard_)) {
      if (std::chrono::steady_clock::now() >= end) return false;
      if (::poll(&pfd, 1, 20) > 0) lcm_.handle();
    }
    return true;
  }
  // Waits for `n` more heartbeats of `pid`.
  bool more_from(pid_t pid, int n) {
    const auto start = count(pid);
    return until([&](const auto&) { return count(pid) >= start + n; });
  }
  std::size_t count(pid_t pid) const {
    return static_cast<std::size_t>(std::count_if(heard_.begin(), heard_.end(), [&](const auto& s) { return s.pid == pid; }));
  }
  // Waits for `n` heartbeats of `pid` sent after `time_us` (one host: one clock).
  bool sent_after(pid_t pid, std::int64_t time_us, int n) {
    return until([&](const auto& heard) {
      return std::count_if(heard.begin(), heard.end(), [&](const auto& s) { return s.pid == pid && s.time_us > time_us; }) >= n;
    });
  }
  // The senders of the heartbeats sent after `time_us`. Those sent earlier may arrive
  // later, from our socket's queue.
  std::set<pid_t> pids_sent_after(std::int64_t time_us) const {
    std::set<pid_t> out;
    for (const auto& s : heard_)
      if (s.time_us > time_us) out.insert(s.pid);
    return out;
  }

 private:
  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (auto s = decode_status(channel, bytes_of(rbuf->data, rbuf->data_size))) heard_.push_back(*s);
  }
  lcm::LCM lcm_;
  std::vector<device_status_t> heard_;
};

// Waits for one of the two daemons to exit; which, or nothing after `seconds`.
Daemon* first_to_exit(Daemon& a, Daemon& b, int& status, double seconds = 20) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    for (Daemon* d : {&a, &b})
      if (auto s = d->process->wait(0.005)) {
        status = *s;
        return d;
      }
  }
  return nullptr;
}

bool exited_with(const std::optional<int>& status, int code) {
  return status && WIFEXITED(*status) && WEXITSTATUS(*status) == code;
}

std::string holder(pid_t pid) { return fmt::format("covtrackd on {}/{} (instance ", host_name(), pid); }

}  // namespace

TEST(Ownership, ASecondDaemonRefusesTheDeviceNamingTheHolderAndANewOneTakesItOnceTheFirstIsKilled) {
  const std::string url = url_for(7731);
  HeartbeatLog heartbeats(url);
  ASSERT_TRUE(heartbeats.good());
  auto sub = client::Subscriber::open({.lcm_url = url});
  ASSERT_TRUE(sub) << sub.error().message;
  const std::string config = write_config("refuse", config_text());

  Daemon first("first", config, url);
  ASSERT_TRUE(heartbeats.more_from(first.pid(), 2)) << first.output();

  Daemon second("second", config, url);
  const auto status = second.process->wait(20);
  EXPECT_TRUE(exited_with(status, 1)) << second.output();
  const std::string said = second.output();
  EXPECT_NE(said.find("device 'rig' not started: " + holder(first.pid())), std::string::npos) << said;
  EXPECT_NE(said.find("already publishes it"), std::string::npos) << said;
  EXPECT_NE(said.find("every configured device is published by another daemon"), std::string::npos) << said;

  // Heartbeats go on from the first alone; the client hears one publisher and no loss.
  ASSERT_TRUE(heartbeats.more_from(first.pid(), 5));
  EXPECT_EQ(heartbeats.count(second.pid()), 0u) << "the refused daemon sent a heartbeat";
  const auto devices = (*sub)->devices();
  ASSERT_TRUE(devices.contains("rig"));
  EXPECT_EQ(devices.at("rig").publishers, 1);
  ASSERT_EQ(devices.at("rig").publishing.size(), 1u);
  EXPECT_EQ(devices.at("rig").publishing[0].pid, first.pid());
  const auto stream = (*sub)->stream({"rig", "s0"});
  ASSERT_TRUE(stream);
  EXPECT_GT(stream->counters.received, 0);
  EXPECT_EQ(stream->counters.lost, 0);
  EXPECT_EQ(stream->counters.foreign, 0);

  // The holder dies without a word; a daemon started then takes the device.
  int killed = 0;
  ASSERT_GE(first.process->stop(SIGKILL, killed), 0);
  Daemon third("third", config, url);
  EXPECT_TRUE(heartbeats.until([&](const auto& heard) {
    return !heard.empty() && heard.back().pid == third.pid() && heard.back().state == device_status_t::STATE_RUNNING;
  })) << third.output();
  EXPECT_FALSE(third.process->wait(0)) << third.output();
}

TEST(Ownership, TwoDaemonsStartedAtOnceLeaveExactlyOnePublisher) {
  const std::string url = url_for(7732);
  HeartbeatLog heartbeats(url);
  ASSERT_TRUE(heartbeats.good());
  const std::string config = write_config("race", config_text());
  Daemon a("race_a", config, url);
  Daemon b("race_b", config, url);

  int status = 0;
  Daemon* loser = first_to_exit(a, b, status);
  ASSERT_TRUE(loser) << "both still run:\n" << a.output() << "\n" << b.output();
  Daemon* winner = loser == &a ? &b : &a;
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << loser->output();
  EXPECT_NE(loser->output().find(holder(winner->pid())), std::string::npos) << loser->output();

  // From the loser's exit on, heartbeats come from the winner alone, which keeps running.
  const std::int64_t exited_us = now_us();
  ASSERT_TRUE(heartbeats.sent_after(winner->pid(), exited_us, 5)) << winner->output();
  EXPECT_EQ(heartbeats.pids_sent_after(exited_us), std::set<pid_t>{winner->pid()});
  EXPECT_FALSE(winner->process->wait(0)) << winner->output();
}

TEST(Ownership, DaemonsOnAnotherGroupOfTheSamePortDoNotCountAsHolders) {
  // Two labs on one network, each its own multicast group, the same port: the second
  // daemon must not hear the first's claims and heartbeats (a socket bound to any
  // address on the port would).
  const std::string url = url_for(7734);
  const std::string other_url = "udpm://239.255.76.68:7734?ttl=0";
  HeartbeatLog heartbeats(other_url);
  ASSERT_TRUE(heartbeats.good());
  const std::string config = write_config("groups", config_text());
  Daemon first("groups_first", config, url);
  Daemon second("groups_second", config, other_url);
  // Past the claim wait, the second publishes the device as its own.
  ASSERT_TRUE(heartbeats.more_from(second.pid(), 5)) << second.output();
  EXPECT_FALSE(second.process->wait(0)) << second.output();
  EXPECT_FALSE(first.process->wait(0)) << first.output();
  EXPECT_EQ(second.output().find("not started"), std::string::npos) << second.output();
}

TEST(Ownership, WithoutAClaimWaitTheLaterClaimGivesTheDeviceUpWhenTheHeartbeatsMeet) {
  const std::string url = url_for(7733);
  HeartbeatLog heartbeats(url);
  ASSERT_TRUE(heartbeats.good());
  const std::string config = write_config("late", config_text("claim_wait_s = 0\n"));
  Daemon first("late_first", config, url);
  ASSERT_TRUE(heartbeats.more_from(first.pid(), 1)) << first.output();

  Daemon second("late_second", config, url);
  // With no wait it starts the device, and publishes, until it hears the first.
  const auto status = second.process->wait(20);
  EXPECT_TRUE(exited_with(status, 1)) << second.output();
  const std::string said = second.output();
  EXPECT_NE(said.find("device 'rig' stopped: " + holder(first.pid())), std::string::npos) << said;
  EXPECT_NE(said.find("claimed it first"), std::string::npos) << said;
  EXPECT_NE(said.find("every device is now published by another daemon"), std::string::npos) << said;

  const std::int64_t exited_us = now_us();
  ASSERT_TRUE(heartbeats.sent_after(first.pid(), exited_us, 5));
  EXPECT_EQ(heartbeats.pids_sent_after(exited_us), std::set<pid_t>{first.pid()});
}

TEST(Ownership, AllowedDuplicatesBothPublishAndEveryoneNamesBoth) {
  const std::string url = url_for(7734);
  HeartbeatLog heartbeats(url);
  ASSERT_TRUE(heartbeats.good());
  auto sub = client::Subscriber::open({.lcm_url = url});
  ASSERT_TRUE(sub) << sub.error().message;
  const std::string config = write_config("dup", config_text());
  Daemon first("dup_first", config, url);
  ASSERT_TRUE(heartbeats.more_from(first.pid(), 1)) << first.output();
  Daemon second("dup_second", config, url, {"--allow-duplicate-publishers"});
  ASSERT_TRUE(heartbeats.more_from(second.pid(), 3)) << second.output();
  ASSERT_TRUE(heartbeats.more_from(first.pid(), 3));

  const auto devices = (*sub)->devices();
  ASSERT_TRUE(devices.contains("rig"));
  const std::string host = host_name();
  EXPECT_EQ(client::second_publisher_warning("rig", devices.at("rig")),
            fmt::format("device rig published by two daemons: {}/{} and {}/{}", host, first.pid(), host, second.pid()));

  // covtrack echo says it too, on stderr (its --json output has no table).
  const std::string echo = fmt::format("{}/tools/covtrack/covtrack echo -u '{}' --json --duration 1 2>&1 >/dev/null",
                                       COVTRACK_BINARY_DIR, url);
  std::string echoed;
  if (FILE* out = ::popen(echo.c_str(), "r")) {
    char buf[4096];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, out)) echoed.append(buf, n);
    EXPECT_EQ(::pclose(out), 0) << echoed;
  }
  // In the order echo first heard them.
  const auto said = [&](pid_t one, pid_t other) {
    return echoed.find(fmt::format("covtrack echo: device rig published by two daemons: {}/{} and {}/{}", host, one,
                                   host, other)) != std::string::npos;
  };
  EXPECT_TRUE(said(first.pid(), second.pid()) || said(second.pid(), first.pid())) << echoed;

  int status = 0;
  EXPECT_GE(second.process->stop(SIGTERM, status), 0);
  EXPECT_GE(first.process->stop(SIGTERM, status), 0);
  EXPECT_NE(second.output().find("device 'rig' is also published by " + holder(first.pid())), std::string::npos)
      << second.output();
  EXPECT_NE(second.output().find("publishing it anyway"), std::string::npos) << second.output();
  EXPECT_NE(first.output().find("device 'rig' is also published by " + holder(second.pid())), std::string::npos)
      << first.output();
}
