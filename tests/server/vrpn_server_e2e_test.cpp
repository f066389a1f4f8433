// covtrackd's VRPN server against clients, good and bad: a client over TCP gets each
// stream as its sensor, equal to what LCM carries; a client that asks over UDP, as VRPN's
// clients do by default, is called back and gets its reports over UDP; a client sending
// bytes no VRPN peer sends, and one that does not read, are dropped with a logged reason
// while the daemon goes on publishing and serving the others. Separate covtrackd
// processes, inside a private network namespace.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>

#include <covtrack/pose_cov_t.hpp>

#include "covtrack/vrpn/cookie.hpp"
#include "daemon_process.hpp"
#include "vrpn_test_client.hpp"

using namespace covtrack;

namespace {

const std::string kUrl = "udpm://239.255.76.67:7752?ttl=0";

// A daemon with two sim sensors served as Tracker0, its log in a file.
// The tests' ports are below 32768, outside Linux's ephemeral range (32768-60999): at 38864
// a client socket of an earlier test here once held the port, and the daemon could not bind.
class ServingDaemon {
 public:
  ServingDaemon(int port, int rate_hz, std::size_t max_queued_bytes = 262144, const std::string& name = "first") {
    const std::string base = ::testing::TempDir() + "/vrpn_server_" + name + std::to_string(port);
    log_ = base + ".log";
    std::ofstream(base + ".toml") << fmt::format(R"(
[devices.sim]
type = "sim"
sensors = ["head", "wand"]
rate_hz = {}
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.002, 0.002, 0.002]

[vrpn_server]
address = "127.0.0.1"
port = {}
max_queued_bytes = {}

[[vrpn_server.trackers]]
name = "Tracker0"
streams = ["sim/head", "sim/wand"]
)",
                                                 rate_hz, port, max_queued_bytes);
    process_ = std::make_unique<test::DaemonProcess>(
        std::vector<std::string>{"--config", base + ".toml", "--lcm-url", kUrl, "--log-level", "info"}, log_);
  }
  std::string log() const {
    std::stringstream s;
    s << std::ifstream(log_).rdbuf();
    return s.str();
  }
  // Waits until the log holds `text`.
  bool log_shows(const std::string& text, double seconds) const {
    for (const auto end = test::after_s(seconds); test::SteadyClock::now() < end;) {
      if (log().find(text) != std::string::npos) return true;
      pollfd none{-1, 0, 0};
      ::poll(&none, 0, 20);
    }
    return false;
  }
  std::optional<int> wait(double seconds) { return process_->wait(seconds); }
  // The daemon is still running, and stops cleanly on SIGTERM.
  void expect_clean_stop() {
    int status = 0;
    EXPECT_GE(process_->stop(SIGTERM, status), 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status << "\n" << log();
  }

 private:
  std::string log_;
  std::unique_ptr<test::DaemonProcess> process_;
};

// Counts and keeps the LCM poses of sim/head.
class HeadPoses {
 public:
  HeadPoses() : lcm_(kUrl) {
    lcm_.subscribe("covtrack/pose/sim/.*", &HeadPoses::on_pose, this)->setQueueCapacity(100000);
  }
  void handle_pending() {
    pollfd p{lcm_.getFileno(), POLLIN, 0};
    while (::poll(&p, 1, 0) > 0) lcm_.handle();
  }
  std::map<std::string, std::map<std::int64_t, pose_cov_t>> by_sensor;

 private:
  void on_pose(const lcm::ReceiveBuffer*, const std::string&, const pose_cov_t* m) {
    by_sensor[m->sensor][m->measurement_time_us] = *m;
  }
  lcm::LCM lcm_;
};

std::size_t count(const test::VrpnTestClient& c, std::int32_t sensor) {
  const auto it = c.reports.find(sensor);
  return it == c.reports.end() ? 0 : it->second.size();
}

}  // namespace

TEST(VrpnServer, ATcpClientGetsEachStreamAsItsSensorEqualToLcm) {
  HeadPoses lcm;
  ServingDaemon daemon(28861, 100);
  test::VrpnTestClient client;
  ASSERT_TRUE(client.connect_tcp(28861)) << daemon.log();
  ASSERT_TRUE(client.run_until([&] { return count(client, 0) >= 50 && count(client, 1) >= 50 && client.pongs > 0; },
                               20))
      << "sensor 0: " << count(client, 0) << ", sensor 1: " << count(client, 1) << ", pongs " << client.pongs
      << ", " << client.error << "\n" << daemon.log();
  EXPECT_TRUE(client.session().peer()) << "the server's cookie";
  EXPECT_TRUE(client.reports.size() == 2) << "only sensors 0 and 1";
  lcm.handle_pending();
  int compared = 0;
  for (const auto& [sensor, name] : {std::pair{0, "head"}, std::pair{1, "wand"}})
    for (const auto& r : client.reports[sensor]) {
      EXPECT_FALSE(r.by_udp) << "a TCP client gets its reports over TCP";
      const auto& lcm_poses = lcm.by_sensor[name];
      const auto m = lcm_poses.find(r.time_us);
      if (m == lcm_poses.end()) continue;  // LCM may drop a datagram; VRPN's TCP may not
      ++compared;
      for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(r.report.position_m[i], m->second.position_m[i]);
      // VRPN's x y z w against covtrack's w x y z, up to the sign of the whole quaternion.
      const auto& q = r.report.quaternion_xyzw;
      const double* w = m->second.orientation_wxyz;
      EXPECT_NEAR(std::abs(q[3] * w[0] + q[0] * w[1] + q[1] * w[2] + q[2] * w[3]), 1.0, 1e-12);
    }
  EXPECT_GE(compared, 80);
  std::vector<std::int64_t> age_us;
  for (const auto& r : client.reports[0]) age_us.push_back(r.arrival_us - r.time_us);
  std::sort(age_us.begin(), age_us.end());
  std::printf("measurement to VRPN client over TCP: median %lld us, largest %lld us (%zu reports)\n",
              static_cast<long long>(age_us[age_us.size() / 2]), static_cast<long long>(age_us.back()), age_us.size());
  daemon.expect_clean_stop();
}

TEST(VrpnServer, AClientAskingOverUdpIsCalledBackAndGetsReportsOverUdp) {
  ServingDaemon daemon(28862, 100);
  test::VrpnTestClient client;
  ASSERT_TRUE(client.connect_by_udp_request(28862)) << "not called back\n" << daemon.log();
  std::size_t by_udp = 0;
  ASSERT_TRUE(client.run_until(
      [&] {
        by_udp = 0;
        for (const auto& [sensor, list] : client.reports)
          for (const auto& r : list) by_udp += r.by_udp;
        return by_udp >= 50 && client.pongs > 0;
      },
      20))
      << by_udp << " reports over UDP, pongs " << client.pongs << "\n" << daemon.log();
  EXPECT_TRUE(daemon.log_shows("asked over UDP; calling it back", 1)) << daemon.log();
  daemon.expect_clean_stop();
}

TEST(VrpnServer, MalformedClientsAreDroppedWithAReasonAndOthersAreServed) {
  ServingDaemon daemon(28863, 100);
  test::VrpnTestClient good;
  ASSERT_TRUE(good.connect_tcp(28863));
  ASSERT_TRUE(good.run_until([&] { return count(good, 0) >= 10; }, 20)) << daemon.log();

  // Not VRPN at all.
  test::VrpnTestClient http;
  ASSERT_TRUE(http.connect_tcp(28863));
  const std::string request = "GET / HTTP/1.1\r\nHost: x\r\n\r\n";
  EXPECT_TRUE(http.send_raw(std::vector<std::uint8_t>(request.begin(), request.end())));
  EXPECT_TRUE(http.closed_by_server_within(10)) << daemon.log();
  EXPECT_TRUE(daemon.log_shows("not a VRPN peer of major version 07: it sent 'GET / HTTP/1.1", 5)) << daemon.log();

  // A VRPN cookie, then a header no VRPN sender writes (a length below the header).
  test::VrpnTestClient broken;
  ASSERT_TRUE(broken.connect_tcp(28863));
  const vrpn::Cookie cookie = vrpn::make_cookie();
  std::vector<std::uint8_t> bytes(cookie.begin(), cookie.end());
  for (std::uint8_t b : {0, 0, 0, 4}) bytes.push_back(b);
  bytes.resize(bytes.size() + 20, 0);
  EXPECT_TRUE(broken.send_raw(bytes));
  EXPECT_TRUE(broken.closed_by_server_within(10)) << daemon.log();
  EXPECT_TRUE(daemon.log_shows("malformed VRPN input: VRPN message length 4 is below the 24-byte header", 5))
      << daemon.log();

  // Silent: no cookie ever.
  test::VrpnTestClient silent;
  ASSERT_TRUE(silent.connect_tcp(28863));
  ASSERT_TRUE(silent.send_raw({}));
  EXPECT_TRUE(silent.closed_by_server_within(15)) << daemon.log();
  EXPECT_TRUE(daemon.log_shows("no VRPN handshake within 5 s", 5)) << daemon.log();

  // A datagram on the UDP port that is no connection request.
  auto udp = vrpn::connect_udp(vrpn::ipv4_address(in_addr{htonl(INADDR_LOOPBACK)}, 28863));
  ASSERT_TRUE(udp);
  ::send(udp->fd(), "\x01\x02garbage", 9, 0);
  EXPECT_TRUE(daemon.log_shows("ignored a malformed UDP connection request", 5)) << daemon.log();

  // The good client was served throughout and still is.
  const std::size_t before = count(good, 0);
  EXPECT_TRUE(good.run_until([&] { return count(good, 0) >= before + 20; }, 10)) << good.error;
  daemon.expect_clean_stop();
}

TEST(VrpnServer, AClientThatDoesNotReadIsDroppedWhilePublishingGoesOn) {
  HeadPoses lcm;
  ServingDaemon daemon(28864, 1000, 8192);
  test::VrpnTestClient reader;
  ASSERT_TRUE(reader.connect_tcp(28864));
  ASSERT_TRUE(reader.run_until([&] { return count(reader, 0) >= 10; }, 20)) << daemon.log();

  // Handshakes, then never reads again, with a small receive buffer.
  test::VrpnTestClient stalled;
  ASSERT_TRUE(stalled.connect_tcp(28864, 10, /*receive_buffer=*/4096));
  ASSERT_TRUE(stalled.run_until([&] { return stalled.session().ready(); }, 10));
  lcm.handle_pending();
  const std::size_t lcm_before = lcm.by_sensor["head"].size();
  const std::size_t vrpn_before = count(reader, 0);
  const auto t0 = test::SteadyClock::now();
  // Meanwhile the reading client keeps reading, so that its own buffer never fills.
  ASSERT_TRUE(reader.run_until([&] { return daemon.log().find("the client does not read") != std::string::npos; },
                               60))
      << daemon.log();
  const double stalled_s = std::chrono::duration<double>(test::SteadyClock::now() - t0).count();
  lcm.handle_pending();
  const double lcm_rate = static_cast<double>(lcm.by_sensor["head"].size() - lcm_before) / stalled_s;
  const double vrpn_rate = static_cast<double>(count(reader, 0) - vrpn_before) / stalled_s;
  std::printf("stalled client dropped after %.2f s; meanwhile sim/head on LCM %.0f Hz, to the reading VRPN client "
              "%.0f Hz (configured 1000 Hz)\n",
              stalled_s, lcm_rate, vrpn_rate);
  // Not a speed assertion: a stalled publish loop would publish nothing at all.
  EXPECT_GT(lcm_rate, 100);
  EXPECT_GT(vrpn_rate, 100);
  EXPECT_TRUE(stalled.closed_by_server_within(10));
  daemon.expect_clean_stop();
}

TEST(VrpnServer, APortInUseStopsTheStartWithCode1NamingTheAddress) {
  ServingDaemon first(28865, 100);
  test::VrpnTestClient client;
  ASSERT_TRUE(client.connect_tcp(28865)) << "the first daemon serves";
  ServingDaemon second(28865, 100, 262144, "second");
  const auto status = second.wait(10);
  ASSERT_TRUE(status) << "the second daemon did not exit\n" << second.log();
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 1) << "status " << *status;
  EXPECT_NE(second.log().find("vrpn_server: cannot bind TCP 127.0.0.1:28865"), std::string::npos) << second.log();
  first.expect_clean_stop();
}
