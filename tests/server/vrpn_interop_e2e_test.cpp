// covtrack's VRPN client (the vrpn driver) against covtrack's VRPN server: one covtrackd
// serves its sim trackers to VRPN, a second covtrackd reads them with the vrpn driver and
// republishes them on LCM. The republished poses must equal the source's, with the
// covariance the relay's config gives; when the serving daemon dies the relay reports
// LOST, and when it comes back the relay recovers by itself. Separate processes, inside
// a private network namespace.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>

#include <covtrack/pose_cov_t.hpp>

#include "daemon_process.hpp"
#include "vrpn_test_client.hpp"

using namespace covtrack;

namespace {

const std::string kUrl = "udpm://239.255.76.67:7751?ttl=0";

std::string source_config(int port) {
  return fmt::format(R"(
[devices.sim]
type = "sim"
sensors = ["head", "wand"]
rate_hz = 100
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.002, 0.002, 0.002]

[vrpn_server]
address = "127.0.0.1"
port = {}

[[vrpn_server.trackers]]
name = "Tracker0"
streams = ["sim/head", "sim/wand"]
)",
                     port);
}

// head has its own covariance, wand the device's.
std::string relay_config(int port) {
  return fmt::format(R"(
[daemon]
restart_backoff_initial_s = 0.2
restart_backoff_max_s = 0.5

[devices.relay]
type = "vrpn"
tracker = "Tracker0@127.0.0.1:{}"
sigma_m = [0.01, 0.02, 0.03]
sigma_rad = [0.04, 0.05, 0.06]

[[devices.relay.sensors]]
number = 0
name = "head"
sigma_m = [0.001, 0.001, 0.002]
sigma_rad = [0.003, 0.003, 0.004]

[[devices.relay.sensors]]
number = 1
name = "wand"
)",
                     port);
}

std::string write_config(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name + "_" + std::to_string(getpid()) + ".toml";
  std::ofstream(path) << text;
  return path;
}

std::unique_ptr<test::DaemonProcess> start_daemon(const std::string& name, const std::string& config) {
  const std::string log = ::testing::TempDir() + "/" + name + "_" + std::to_string(getpid()) + ".log";
  return std::make_unique<test::DaemonProcess>(
      std::vector<std::string>{"--config", write_config(name, config), "--lcm-url", kUrl, "--log-level", "info"}, log);
}

// Every pose of the four streams, by stream and measurement time.
class Poses {
 public:
  Poses() : lcm_(kUrl) { lcm_.subscribe("covtrack/pose/.*", &Poses::on_pose, this)->setQueueCapacity(100000); }
  bool until(const std::function<bool()>& done, double seconds) {
    pollfd p{lcm_.getFileno(), POLLIN, 0};
    for (const auto end = test::after_s(seconds); test::SteadyClock::now() < end && !done();)
      if (::poll(&p, 1, 20) > 0) lcm_.handle();
    return done();
  }
  std::map<std::string, std::map<std::int64_t, pose_cov_t>> by_stream;
  std::map<std::string, std::vector<pose_cov_t>> in_order;

 private:
  void on_pose(const lcm::ReceiveBuffer*, const std::string&, const pose_cov_t* m) {
    const std::string stream = m->device + "/" + m->sensor;
    by_stream[stream][m->measurement_time_us] = *m;
    in_order[stream].push_back(*m);
  }
  lcm::LCM lcm_;
};

Mat6 diagonal(const std::array<double, 6>& sigma) {
  Mat6 c = Mat6::Zero();
  for (int i = 0; i < 6; ++i) c(i, i) = sigma[static_cast<std::size_t>(i)] * sigma[static_cast<std::size_t>(i)];
  return c;
}

// Relayed poses matched to the source by measurement time (the VRPN header carries it).
int matched(Poses& poses, const std::string& source, const std::string& relay) {
  int n = 0;
  for (const auto& [t, m] : poses.by_stream[relay])
    if (poses.by_stream[source].count(t) && m.status == pose_cov_t::STATUS_OK) ++n;
  return n;
}

}  // namespace

TEST(VrpnInterop, RelayedPosesEqualTheSourceWithTheConfiguredCovariance) {
  const int port = 28851;  // below Linux's ephemeral ports (32768-60999): no client socket holds it
  Poses poses;
  auto source = start_daemon("vrpn_source", source_config(port));
  auto relay = start_daemon("vrpn_relay", relay_config(port));
  ASSERT_TRUE(poses.until([&] { return matched(poses, "sim/head", "relay/head") >= 100 &&
                                       matched(poses, "sim/wand", "relay/wand") >= 100; },
                          30))
      << "relayed poses matched by time: head " << matched(poses, "sim/head", "relay/head") << ", wand "
      << matched(poses, "sim/wand", "relay/wand");

  const std::map<std::string, Mat6> expected_covariance = {
      {"head", diagonal({0.001, 0.001, 0.002, 0.003, 0.003, 0.004})},
      {"wand", diagonal({0.01, 0.02, 0.03, 0.04, 0.05, 0.06})}};
  for (const std::string sensor : {"head", "wand"}) {
    double worst_m = 0, worst_quat = 0;
    for (const auto& [t, r] : poses.by_stream["relay/" + sensor]) {
      const auto s = poses.by_stream["sim/" + sensor].find(t);
      if (s == poses.by_stream["sim/" + sensor].end()) continue;
      for (int i = 0; i < 3; ++i) worst_m = std::max(worst_m, std::abs(r.position_m[i] - s->second.position_m[i]));
      double dot = 0;  // q and -q are one rotation
      for (int i = 0; i < 4; ++i) dot += r.orientation_wxyz[i] * s->second.orientation_wxyz[i];
      worst_quat = std::max(worst_quat, 1 - std::abs(dot));
      EXPECT_EQ(r.parent_frame, "world");
      EXPECT_EQ(r.child_frame, sensor);
      const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> c(r.covariance);
      ASSERT_TRUE(c.isApprox(expected_covariance.at(sensor), 1e-12)) << sensor << ":\n" << c;
    }
    // VRPN carries doubles: float precision is a loose bound (measured: exact to 1e-16).
    EXPECT_LT(worst_m, 1e-6) << sensor;
    EXPECT_LT(worst_quat, 1e-12) << sensor;
    std::printf("%s: largest position difference %.3g m, 1-|q.q'| %.3g\n", sensor.c_str(), worst_m, worst_quat);
  }
}

TEST(VrpnInterop, TheRelayReportsLostWhenTheServerDiesAndRecoversWhenItReturns) {
  const int port = 28852;
  Poses poses;
  auto source = start_daemon("vrpn_source", source_config(port));
  auto relay = start_daemon("vrpn_relay", relay_config(port));
  const auto count_ok = [&](std::size_t from) {
    int n = 0;
    const auto& v = poses.in_order["relay/head"];
    for (std::size_t i = from; i < v.size(); ++i) n += v[i].status == pose_cov_t::STATUS_OK;
    return n;
  };
  ASSERT_TRUE(poses.until([&] { return count_ok(0) >= 20; }, 30)) << "the relay never published";

  int status = 0;
  ASSERT_GE(source->stop(SIGKILL, status), 0);
  std::size_t lost_at = 0;
  ASSERT_TRUE(poses.until(
      [&] {
        const auto& v = poses.in_order["relay/head"];
        for (std::size_t i = 0; i < v.size(); ++i)
          if (v[i].status == pose_cov_t::STATUS_LOST) return (lost_at = i + 1) > 0;
        return false;
      },
      10))
      << "no LOST after the serving daemon died";
  EXPECT_TRUE(std::isinf(poses.in_order["relay/head"][lost_at - 1].covariance[0])) << "LOST carries no information";
  EXPECT_EQ(count_ok(lost_at), 0) << "nothing OK while the server is away";

  source = start_daemon("vrpn_source", source_config(port));
  ASSERT_TRUE(poses.until([&] { return count_ok(lost_at) >= 20; }, 30)) << "the relay did not recover";
  EXPECT_TRUE(poses.until([&] { return matched(poses, "sim/wand", "relay/wand") > 0; }, 10));
}
