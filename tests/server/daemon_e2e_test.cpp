// End to end, as separate processes, inside a private network namespace (see
// tests/netns_run.sh): covtrackd publishing over real UDP multicast, a subscriber here.
#include <gtest/gtest.h>


#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <random>

#include <lcm/lcm-cpp.hpp>

#include <covtrack/device_status_t.hpp>
#include <covtrack/pose_cov_t.hpp>
#include <covtrack/truth_pose_t.hpp>

#include "covtrack/protocol/pose_message.hpp"
#include "daemon_process.hpp"

using namespace covtrack;

namespace {

// A distinct port per test keeps tests apart (LCM 1.3.1: groups on one port cross-talk).
std::string url_for(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=8388608";
}

struct StreamLog {
  std::int64_t received = 0, gaps = 0, last_sequence = -1;
  std::int64_t max_interval_us = 0, first_receive_us = 0, last_receive_us = 0;
  std::int64_t first_measured_us = 0, last_measured_us = 0;  // the reports' own times
  std::map<std::int64_t, pose_cov_t> by_time;  // for pairing with the truth
};

class Collector {
 public:
  explicit Collector(const std::string& url) : lcm_(url) {
    lcm_.subscribe("covtrack/pose/.*", &Collector::on_pose, this)->setQueueCapacity(1 << 20);
    lcm_.subscribe("covtrack/truth/.*", &Collector::on_truth, this)->setQueueCapacity(1 << 20);
    lcm_.subscribe("covtrack/status/.*", &Collector::on_status, this)->setQueueCapacity(1000);
  }
  bool good() { return lcm_.good(); }

  void run_for(double seconds) {
    covtrack::test::handle_for(lcm_, seconds);
  }

  std::map<std::string, StreamLog> poses;
  std::map<std::string, std::map<std::int64_t, truth_pose_t>> truths;
  std::map<std::string, device_status_t> status;
  bool keep_samples = false;

 private:
  static std::int64_t now() {
    return std::chrono::duration_cast<std::chrono::microseconds>(
               std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  void on_pose(const lcm::ReceiveBuffer*, const std::string& ch, const pose_cov_t* m) {
    StreamLog& s = poses[ch];
    if (s.last_sequence >= 0 && m->sequence > s.last_sequence + 1)
      s.gaps += m->sequence - s.last_sequence - 1;
    const std::int64_t t = now();
    if (s.last_receive_us) s.max_interval_us = std::max(s.max_interval_us, t - s.last_receive_us);
    if (!s.first_receive_us) s.first_receive_us = t, s.first_measured_us = m->measurement_time_us;
    s.last_receive_us = t;
    s.last_measured_us = m->measurement_time_us;
    s.last_sequence = m->sequence;
    ++s.received;
    if (keep_samples) s.by_time[m->measurement_time_us] = *m;
  }
  void on_truth(const lcm::ReceiveBuffer*, const std::string&, const truth_pose_t* m) {
    if (keep_samples) truths[m->device + "/" + m->sensor][m->measurement_time_us] = *m;
  }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const device_status_t* m) {
    status[m->device] = *m;
  }

  lcm::LCM lcm_;
};

std::string sim_device(const std::string& name, int sensors, double rate_hz,
                       const std::string& extra = "") {
  return "[devices." + name + "]\ntype = \"sim\"\nsensor_count = " + std::to_string(sensors) +
         "\nrate_hz = " + std::to_string(rate_hz) +
         "\nsigma_m = [0.001, 0.002, 0.001]\nsigma_rad = [0.004, 0.002, 0.003]\n" + extra;
}

}  // namespace

TEST(DaemonEndToEnd, TenSensorsAt1kHzWithoutGapsAndStopWithinOneSecond) {
  const std::string url = url_for(7701);
  Collector c(url);
  ASSERT_TRUE(c.good());
  test::DaemonProcess daemon(sim_device("rig", 10, 1000), url);
  // 3500 reports per sensor: about 4.5 s on an idle machine; a loaded one gets longer.
  const auto all_have = [&](std::int64_t n) {
    if (c.poses.size() < 10) return false;
    for (const auto& [channel, s] : c.poses)
      if (s.received <= n) return false;
    return true;
  };
  for (int waited = 0; waited < 40 && !all_have(3500); ++waited) c.run_for(0.5);

  ASSERT_EQ(c.poses.size(), 10u);
  std::int64_t total = 0;
  for (const auto& [channel, s] : c.poses) {
    EXPECT_EQ(s.gaps, 0) << channel;
    EXPECT_GT(s.received, 3500) << channel;
    total += s.received;
  }
  EXPECT_GT(total, 35000);
  ASSERT_TRUE(c.status.count("rig"));
  EXPECT_EQ(int{c.status["rig"].state}, int{device_status_t::STATE_RUNNING});
  EXPECT_NEAR(c.status["rig"].rate_hz, 10000, 1500);
  // The heartbeat names its publisher and its period (sim_device's daemon: 1 Hz).
  char host[256] = {};
  ASSERT_EQ(gethostname(host, sizeof host - 1), 0);
  EXPECT_EQ(c.status["rig"].host, host);
  EXPECT_EQ(c.status["rig"].pid, daemon.pid());
  EXPECT_NE(c.status["rig"].instance_id, 0);
  EXPECT_EQ(c.status["rig"].heartbeat_period_us, 1'000'000);

  int status = 0;
  const double stop_s = daemon.stop(SIGTERM, status);
  EXPECT_GE(stop_s, 0.0) << "covtrackd did not exit within 5 s of SIGTERM";
  EXPECT_LT(stop_s, 1.0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

TEST(DaemonEndToEnd, NeesAgainstTheTruthChannelIsChiSquare6) {
  const std::string url = url_for(7702);
  Collector c(url);
  c.keep_samples = true;
  // A fresh noise seed per run: with the default seed every run would test the same
  // draws, and a seed whose first draws sit near the bound would fail every time.
  const std::uint64_t seed = std::random_device{}() % 1000000;
  test::DaemonProcess daemon(sim_device("rig", 4, 1000, "seed = " + std::to_string(seed) + "\n"),
                             url);
  // Until 8000 poses have their truth (2 s at full rate), not for a fixed time: a slow
  // start on a loaded machine only makes the wait longer.
  const auto pairs = [&] {
    int n = 0;
    for (const auto& [channel, s] : c.poses)
      for (const auto& [t, msg] : s.by_time) n += c.truths[msg.device + "/" + msg.sensor].count(t) > 0;
    return n;
  };
  for (int waited = 0; waited < 60 && pairs() < 8000; ++waited) c.run_for(0.5);

  Mat6 cov = Mat6::Zero();
  cov.diagonal() << 1e-6, 4e-6, 1e-6, 16e-6, 4e-6, 9e-6;
  const Mat6 info = cov.inverse();
  double sum = 0;
  int n = 0;
  for (const auto& [channel, s] : c.poses) {
    for (const auto& [t, msg] : s.by_time) {
      auto& truth = c.truths[msg.device + "/" + msg.sensor];
      auto it = truth.find(t);
      if (it == truth.end()) continue;
      const Mat6 reported = body_covariance_of(msg);
      ASSERT_LT((reported - cov).norm(), 1e-12);  // the wire carries the configured covariance
      const Vec6 e = boxminus(pose_of(it->second), pose_of(msg));
      sum += e.dot(info * e);
      ++n;
    }
  }
  ASSERT_GE(n, 8000);
  // NEES of n independent pairs: mean 6, variance 12/n. Two-sided bound at 4.42 sigma, so
  // an honest covariance fails one run in 100,000 (at 3.29 sigma, one in a thousand, it
  // did fail a CI run: mean 5.82 over 4576 pairs); a variance 5% off moves the mean by
  // 0.3, 7.7 sigma at 8000 pairs, and fails 99.9% of runs.
  const double mean = sum / n;
  EXPECT_NEAR(mean, 6.0, 4.42 * std::sqrt(12.0 / n)) << "over " << n << " pairs, seed " << seed;
}

TEST(DaemonEndToEnd, FailingDeviceRestartsWhileTheOtherKeepsPublishing) {
  const std::string url = url_for(7703);
  Collector c(url);
  const std::string config =
      "[daemon]\nrestart_backoff_initial_s = 0.2\nrestart_backoff_max_s = 0.4\nheartbeat_hz = 20\n" +
      sim_device("steady", 1, 200) +
      sim_device("flaky", 1, 200, "inject_failure_every_s = 0.3\n");
  test::DaemonProcess daemon(config, url);
  // 3 s at least, and until the flaky device has failed twice (its failures come every
  // 0.3 s of its own running time, which a loaded machine stretches).
  c.run_for(3.0);
  const auto restarts = [&]() -> std::int64_t { return c.status.count("flaky") ? c.status["flaky"].restarts : 0; };
  for (int waited = 0; waited < 60 && restarts() < 2; ++waited) c.run_for(0.5);

  const StreamLog steady = c.poses["covtrack/pose/steady/s0"];  // as it stands now
  // Every tick of the steady device's schedule over the span of its reports is accounted
  // for: published, or skipped and counted as a drop where the machine held the daemon
  // up for more than 10 ticks (sim_driver.cpp). Counted by the reports' own times, not in
  // a fixed window (a slow start-up shortens it), and with the drops: the received rate
  // alone reads the machine (a CI run with the instrumented build beside the suite
  // received 401 reports over 2.28 s at 200 Hz, with no gap and no stall; four busy loops
  // beside this test gave 321 reports and 51 drops over 1.86 s). The drops are those of
  // the first heartbeat (20 Hz here) sent after the last of these reports.
  const auto heard_after = [&](std::int64_t time_us) {
    return c.status.count("steady") && c.status["steady"].time_us >= time_us;
  };
  for (int waited = 0; waited < 40 && !heard_after(steady.last_measured_us); ++waited) c.run_for(0.05);
  ASSERT_TRUE(heard_after(steady.last_measured_us)) << "no heartbeat of the steady device after its reports";
  const double span_s = (steady.last_measured_us - steady.first_measured_us) * 1e-6;
  const std::int64_t drops = c.status["steady"].drops;
  std::printf("steady: %lld reports received and %lld dropped over %.3f s of their times (%.3f s received)\n",
              static_cast<long long>(steady.received), static_cast<long long>(drops), span_s,
              (steady.last_receive_us - steady.first_receive_us) * 1e-6);
  EXPECT_GT(span_s, 1.5);
  EXPECT_GT(steady.received + drops, 0.95 * 200 * span_s) << "over " << span_s << " s, " << drops << " dropped";
  EXPECT_EQ(steady.gaps, 0);
  // A stall caused by the flaky device's restarts would last at least its back-off
  // (0.2 s); below that bound lie the scheduling hiccups of a loaded 2-core machine
  // (82 ms seen with parallel builds running).
  EXPECT_LT(steady.max_interval_us, 150000) << "the steady device stalled";
  ASSERT_TRUE(c.status.count("flaky"));
  EXPECT_GE(c.status["flaky"].restarts, 2);
  EXPECT_GE(c.status["flaky"].errors, 2);
  EXPECT_NE(c.status["flaky"].last_error.find("injected failure"), std::string::npos);
  // Sequence numbers survive restarts: the flaky stream has no gaps either.
  EXPECT_EQ(c.poses["covtrack/pose/flaky/s0"].gaps, 0);
  EXPECT_EQ(c.status["steady"].restarts, 0);
}

TEST(DaemonEndToEnd, SigintStopsToo) {
  const std::string url = url_for(7704);
  test::DaemonProcess daemon(sim_device("rig", 1, 100), url);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  int status = 0;
  const double stop_s = daemon.stop(SIGINT, status);
  EXPECT_GE(stop_s, 0.0);
  EXPECT_LT(stop_s, 1.0);
}
