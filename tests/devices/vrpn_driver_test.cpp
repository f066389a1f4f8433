// The vrpn driver against a scripted VRPN server on loopback: reports become poses with
// the configured covariance; a report of an unlisted sensor, of the wrong size or with a
// time stamp far from this host's clock is counted; a dropped connection makes every
// reporting sensor LOST; a server that is no VRPN server, or serves no device of the
// configured name, fails the driver with an error saying so. Driver and server run on
// simulated time (manual_clock.hpp): the timeouts pass in steps, not in wall time.
#include <gtest/gtest.h>

#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <thread>

#include "capture_sink.hpp"
#include "covtrack/devices/vrpn/vrpn_driver.hpp"
#include "covtrack/vrpn/message_names.hpp"
#include "covtrack/vrpn/session.hpp"
#include "covtrack/vrpn/socket.hpp"
#include "covtrack/vrpn/tracker_report.hpp"
#include "manual_clock.hpp"

using namespace covtrack;
using namespace covtrack::vrpn;

namespace {

// The scripted server's end of a connection. The server moves in step with the driver on
// the test's clock: each of its waits is one step, so that simulated time passes only while
// both sides wait, however slowly either of them runs.
struct Peer {
  const Socket& socket;
  test::ManualClock& clock;
  std::stop_token stop;

  // Waits for the clock's next step, then says whether there is something to read (or
  // the end of the connection).
  bool readable_next_step() const { return readable_next_step(socket.fd(), clock, stop); }
  static bool readable_next_step(int fd, test::ManualClock& clock, std::stop_token stop) {
    clock.sleep_until(stop, clock.now() + std::chrono::nanoseconds(1));
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, 0) > 0;
  }
};

// Accepts one connection on a loopback port and runs `script` on it, on its own thread,
// in step with `clock`.
class ScriptedServer {
 public:
  ScriptedServer(test::ManualClock& clock, std::function<void(const Peer&)> script) {
    auto listener = listen_tcp("127.0.0.1", 0);
    EXPECT_TRUE(listener);
    sockaddr_in a{};
    socklen_t size = sizeof a;
    getsockname(listener->fd(), reinterpret_cast<sockaddr*>(&a), &size);
    port = ntohs(a.sin_port);
    clock.join();
    thread_ = std::jthread([l = std::move(*listener), &clock, script](std::stop_token stop) {
      while (!stop.stop_requested())
        if (Peer::readable_next_step(l.fd(), clock, stop)) {
          Socket s(::accept(l.fd(), nullptr, nullptr));
          script(Peer{s, clock, stop});
          break;
        }
      clock.leave();
    });
  }
  int port = 0;

 private:
  std::jthread thread_;
};

// Reads from the peer into `session` until it has the peer's cookie (or 250 steps pass).
void handshake(const Peer& peer, Session& session) {
  send_all(peer.socket, session.take_output(), 2);
  std::array<std::uint8_t, 4096> buffer{};
  for (int i = 0; i < 250 && !session.ready(); ++i)
    if (peer.readable_next_step()) {
      const ssize_t n = ::recv(peer.socket.fd(), buffer.data(), buffer.size(), 0);
      if (n <= 0) return;
      (void)session.receive(std::span(buffer.data(), static_cast<std::size_t>(n)), peer.clock.now_us());
    }
  send_all(peer.socket, session.take_output(), 2);
}

// Reads what the peer sends (the driver's pings) until it closes the connection.
void read_until_closed(const Peer& peer) {
  std::array<std::uint8_t, 4096> buffer{};
  while (!peer.stop.stop_requested())
    if (peer.readable_next_step() && ::recv(peer.socket.fd(), buffer.data(), buffer.size(), 0) <= 0) return;
}

// Closes the connection in order: a FIN, then what the peer still sends is read until it
// closes too. A socket closed with unread bytes sends a reset instead, which the driver
// reports as a broken connection, not a closed one.
void close_in_order(const Peer& peer) {
  ::shutdown(peer.socket.fd(), SHUT_WR);
  read_until_closed(peer);
}

Mat6 diagonal(double position_sigma, double rotation_sigma) {
  Mat6 c = Mat6::Zero();
  c.diagonal() << Vec3::Constant(position_sigma * position_sigma), Vec3::Constant(rotation_sigma * rotation_sigma);
  return c;
}

VrpnConfig config_for(int port, const std::string& name = "Tracker0") {
  VrpnConfig c;
  c.device = "relay";
  c.tracker = {name, "127.0.0.1", port};
  c.covariance = diagonal(0.01, 0.02);
  c.sensors = {{0, "head", diagonal(0.001, 0.003)}};
  c.silence_timeout_s = 0.5;
  c.sensor_timeout_s = 0;
  return c;
}

// Runs the driver on `clock` until it returns (within 10 s of simulated time).
Result<void> run_driver(const VrpnConfig& config, test::CaptureSink& sink, test::ManualClock& clock) {
  auto driver = make_vrpn_driver(config, clock);
  std::atomic<bool> returned = false;
  Result<void> result;
  clock.join();
  std::jthread t([&](std::stop_token stop) {
    result = driver->run(sink, stop);
    returned = true;
    clock.leave();
  });
  EXPECT_TRUE(clock.run_until([&] { return returned.load(); }, std::chrono::seconds(10)));
  t.request_stop();
  t.join();
  return result;
}

}  // namespace

TEST(VrpnDriver, ReportsBecomePosesOddOnesAreCountedAndADropIsLost) {
  test::ManualClock clock;
  const std::int64_t t0 = clock.now_us();
  ScriptedServer server(clock, [&](const Peer& peer) {
    Session session({"Tracker0"}, {std::string(kTrackerPosQuat)});
    handshake(peer, session);
    const Pose T = pose_from(Vec3(0.1, -0.2, 1.5), Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vec3(0, 0, 1))));
    session.send("Tracker0", kTrackerPosQuat, t0, encode_pos_quat(report_of(0, T)));
    session.send("Tracker0", kTrackerPosQuat, t0, encode_pos_quat(report_of(5, T)));  // not listed
    auto short_report = encode_pos_quat(report_of(0, T));
    short_report.resize(60);
    session.send("Tracker0", kTrackerPosQuat, t0, short_report);
    session.send("Tracker0", kTrackerPosQuat, t0 - 10'000'000, encode_pos_quat(report_of(0, T)));  // clock 10 s off
    send_all(peer.socket, session.take_output(), 2);
    close_in_order(peer);  // then the server goes away
  });
  test::CaptureSink sink;
  const auto result = run_driver(config_for(server.port), sink, clock);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("closed the connection"), std::string::npos) << result.error().message;
  EXPECT_NE(result.error().message.find("sensors reported LOST"), std::string::npos);

  ASSERT_EQ(sink.poses.size(), 3u) << "two reports of sensor 0, then LOST";
  const PoseSample& first = sink.poses[0];
  EXPECT_EQ(first.sensor, "head");
  EXPECT_EQ(first.parent_frame, "world");
  EXPECT_EQ(first.measurement_time_us, t0) << "the header's time, near this host's clock";
  EXPECT_TRUE(first.T_parent_child.translation().isApprox(Vec3(0.1, -0.2, 1.5), 1e-15));
  EXPECT_TRUE(first.covariance.isApprox(diagonal(0.001, 0.003))) << "the sensor's own covariance";
  EXPECT_GE(sink.poses[1].measurement_time_us, t0) << "a time stamp 10 s off is replaced by the arrival time";
  EXPECT_EQ(sink.poses[2].status, TrackingStatus::Lost);
  EXPECT_TRUE(std::isinf(sink.poses[2].covariance(0, 0)));
  EXPECT_EQ(sink.drops, 1) << "sensor 5 is not listed";
  EXPECT_EQ(sink.errors, 2) << "the 60-byte report and the clock offset";
}

TEST(VrpnDriver, AServerWithoutTheNamedDeviceSaysNamesAreCaseSensitive) {
  test::ManualClock clock;
  ScriptedServer server(clock, [](const Peer& peer) {
    Session session({"tracker0"}, {std::string(kTrackerPosQuat)});
    handshake(peer, session);
    read_until_closed(peer);  // the pings for "Tracker0", answering none
  });
  test::CaptureSink sink;
  const auto result = run_driver(config_for(server.port), sink, clock);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("no device named 'Tracker0' answers"), std::string::npos)
      << result.error().message;
  EXPECT_NE(result.error().message.find("case-sensitive"), std::string::npos);
  EXPECT_TRUE(sink.poses.empty());
}

TEST(VrpnDriver, APeerThatIsNoVrpnServerIsNamedAsSuch) {
  test::ManualClock clock;
  ScriptedServer server(clock, [](const Peer& peer) {
    const std::string banner = "SSH-2.0-OpenSSH_9.2p1 Debian-2\r\n";
    send_all(peer.socket, std::span(reinterpret_cast<const std::uint8_t*>(banner.data()), banner.size()), 2);
    read_until_closed(peer);
  });
  test::CaptureSink sink;
  const auto result = run_driver(config_for(server.port), sink, clock);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("not a VRPN peer of major version 07: it sent 'SSH-2.0-OpenSSH"),
            std::string::npos)
      << result.error().message;
}

TEST(VrpnDriver, NoServerListeningIsAClearError) {
  test::ManualClock clock;
  int port = 0;
  {
    ScriptedServer closed(clock, [](const Peer&) {});
    port = closed.port;
  }  // nothing listens there any more
  test::CaptureSink sink;
  const auto result = run_driver(config_for(port), sink, clock);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("is a vrpn_server running there?"), std::string::npos)
      << result.error().message;
}
