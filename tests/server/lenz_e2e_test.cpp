// End to end as separate processes, inside a private network namespace (NETNS):
// `covtrack emulate-lenz` on a pseudo-terminal -> covtrackd's lenz driver -> LCM -> this
// subscriber; a simulated device runs beside it. The emulator is killed mid-run (its
// pseudo-terminal closes) and started again.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include <covtrack/device_status_t.hpp>
#include <covtrack/pose_cov_t.hpp>
#include <covtrack/raw_bytes_t.hpp>
#include <covtrack/truth_pose_t.hpp>

#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/pose_message.hpp"
#include "daemon_process.hpp"
#include "dead_reckoning.hpp"
#include "support/one_percent_bar.hpp"

using namespace covtrack;

namespace {

const std::string kUrl = "udpm://239.255.76.67:7721?ttl=0&recv_buf_size=8388608";
const std::string kLayout = COVTRACK_SOURCE_DIR "/tests/data/lenz_short_layout.toml";

class Emulator {
 public:
  explicit Emulator(const std::string& link) {
    pid_ = fork();
    if (pid_ == 0) {
      const std::string exe = COVTRACK_BINARY_DIR "/tools/covtrack/covtrack";
      execl(exe.c_str(), exe.c_str(), "emulate-lenz", "--layout", kLayout.c_str(), "--link", link.c_str(),
            "--profile", "0.5:1.5,0.15:1,0:1,0.4:1.5", "--device", "train", "--parent-frame", "world",
            "--lcm-url", kUrl.c_str(), nullptr);
      _exit(127);
    }
    // Ready once the link to its pseudo-terminal exists.
    struct stat st {};
    for (int i = 0; i < 300 && lstat(link.c_str(), &st) != 0; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ~Emulator() { kill_now(); }
  void kill_now() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }

 private:
  pid_t pid_ = -1;
};

struct Sample {
  std::int64_t time_us;
  int status;
  double sigma_along_m;
  Pose pose;
};

class Collector {
 public:
  Collector() : lcm_(kUrl) {
    lcm_.subscribe("covtrack/pose/.*", &Collector::on_pose, this)->setQueueCapacity(1 << 16);
    lcm_.subscribe("covtrack/truth/.*", &Collector::on_truth, this)->setQueueCapacity(1 << 16);
    lcm_.subscribe("covtrack/raw/.*", &Collector::on_raw, this)->setQueueCapacity(1 << 16);
    lcm_.subscribe("covtrack/status/.*", &Collector::on_status, this)->setQueueCapacity(1000);
  }
  bool good() { return lcm_.good(); }
  void run_for(double seconds) {
    covtrack::test::handle_for(lcm_, seconds);
  }

  std::map<std::string, std::vector<Sample>> poses;          // by sensor key device/sensor
  std::map<std::string, std::map<std::int64_t, Pose>> truth;  // by device/sensor, by time
  std::map<std::string, std::int64_t> gaps;
  std::int64_t raw_messages = 0;
  std::map<std::string, device_status_t> status;

 private:
  void on_pose(const lcm::ReceiveBuffer*, const std::string&, const pose_cov_t* m) {
    const std::string key = m->device + "/" + m->sensor;
    auto& list = poses[key];
    if (!list.empty() && m->sequence != last_sequence_[key] + 1) gaps[key] += m->sequence - last_sequence_[key] - 1;
    last_sequence_[key] = m->sequence;
    const double var = m->status == pose_cov_t::STATUS_LOST ? INFINITY : body_covariance_of(*m)(0, 0);
    list.push_back({m->measurement_time_us, m->status, std::sqrt(var), pose_of(*m)});
  }
  void on_truth(const lcm::ReceiveBuffer*, const std::string&, const truth_pose_t* m) {
    truth[m->device + "/" + m->sensor][m->measurement_time_us] = pose_of(*m);
  }
  void on_raw(const lcm::ReceiveBuffer*, const std::string&, const raw_bytes_t*) { ++raw_messages; }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const device_status_t* m) { status[m->device] = *m; }

  lcm::LCM lcm_;
  std::map<std::string, std::int64_t> last_sequence_;
};

int count_status(const std::vector<Sample>& list, int status, std::int64_t from_us, std::int64_t to_us) {
  int n = 0;
  for (const auto& s : list) n += s.status == status && s.time_us >= from_us && s.time_us < to_us;
  return n;
}

}  // namespace

TEST(LenzEndToEnd, EmulatorDaemonClientWithUnplugAndReplug) {
  const std::string link = ::testing::TempDir() + "/covtrack_lenz_e2e_" + std::to_string(getpid());
  Collector c;
  ASSERT_TRUE(c.good());
  auto emulator = std::make_unique<Emulator>(link);
  const std::string config = "[daemon]\nrestart_backoff_initial_s = 0.2\nrestart_backoff_max_s = 0.5\n"
                             "[devices.train]\ntype = \"lenz\"\nparent_frame = \"world\"\nport = \"" + link +
                             "\"\nlayout = \"" + kLayout + "\"\nrate_hz = 30\nkeepalive_s = 0.2\nlink_timeout_s = 1.0\n"
                             "[devices.steady]\ntype = \"sim\"\nsensor_count = 1\nrate_hz = 100\n"
                             "sigma_m = [0.001, 0.001, 0.001]\nsigma_rad = [0.001, 0.001, 0.001]\n";
  test::DaemonProcess daemon(config, kUrl);
  c.run_for(5.0);

  // Tracking: every vehicle reports, DEGRADED (dead reckoning), with raw bytes and truth.
  for (const std::string v : {"loco", "car1", "car2"}) {
    EXPECT_GT(count_status(c.poses["train/" + v], pose_cov_t::STATUS_DEGRADED, 0, INT64_MAX), 60) << v;
    EXPECT_GT(c.truth["train/" + v].size(), 100u) << v;
  }
  EXPECT_GT(c.raw_messages, 20);
  ASSERT_TRUE(c.status.count("train"));
  EXPECT_EQ(int{c.status["train"].state}, int{device_status_t::STATE_RUNNING});

  // Honesty through the whole chain: the locomotive's true position (nearest truth
  // sample in time, allowing for the motion in between) inside the 99% interval.
  int paired = 0, inside = 0;
  const auto& truth = c.truth["train/loco"];
  for (const auto& s : c.poses["train/loco"]) {
    if (s.status != pose_cov_t::STATUS_DEGRADED) continue;
    auto it = truth.lower_bound(s.time_us);
    if (it == truth.end()) continue;
    if (it != truth.begin() && s.time_us - std::prev(it)->first < it->first - s.time_us) --it;
    const double dt = std::abs(static_cast<double>(it->first - s.time_us)) * 1e-6;
    if (dt > 0.05) continue;
    ++paired;
    const double error = (it->second.translation() - s.pose.translation()).norm();
    inside += error <= lenz::kZ99 * s.sigma_along_m + 0.6 * dt + 0.01;  // max speed * dt, track model
  }
  ASSERT_GT(paired, 60);
  // At most as many outside as a true 1% rate reaches in 99% of runs: a bar of 1% of n
  // failed a CI run with 2 of 119 outside, which an exact covariance does in a third of runs.
  const int most_outside = test::most_outside_at_one_percent(paired);
  std::printf("end to end: %d of %d locomotive poses hold the truth inside the 99%% interval (at most %d may not)\n",
              inside, paired, most_outside);
  EXPECT_LE(paired - inside, most_outside);

  // Unplug: kill the emulator; its pseudo-terminal closes.
  const std::int64_t unplugged_us = now_us();
  emulator->kill_now();
  c.run_for(2.5);
  for (const std::string v : {"loco", "car1", "car2"}) {
    const auto& list = c.poses["train/" + v];
    std::int64_t first_lost = -1;
    for (const auto& s : list)
      if (s.time_us >= unplugged_us && s.status == pose_cov_t::STATUS_LOST) {
        first_lost = s.time_us;
        break;
      }
    ASSERT_GE(first_lost, 0) << v << " never went LOST";
    EXPECT_LT(first_lost - unplugged_us, 2'000'000) << v;
  }
  // The other device did not notice.
  const auto& steady = c.poses["steady/s0"];
  EXPECT_GT(count_status(steady, pose_cov_t::STATUS_OK, unplugged_us, INT64_MAX), 200);
  EXPECT_EQ(c.gaps["steady/s0"], 0);

  // Replug: a new emulator on the same path; the driver finds it by itself.
  const std::int64_t replugged_us = now_us();
  emulator = std::make_unique<Emulator>(link);
  c.run_for(2.5);
  for (const std::string v : {"loco", "car1", "car2"})
    EXPECT_GT(count_status(c.poses["train/" + v], pose_cov_t::STATUS_DEGRADED, replugged_us, INT64_MAX), 20) << v;
  EXPECT_EQ(c.gaps["steady/s0"], 0);
  EXPECT_EQ(c.gaps["train/loco"], 0);

  int status = 0;
  EXPECT_GE(daemon.stop(SIGTERM, status), 0.0);
}
