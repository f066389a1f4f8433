#pragma once
// A VRPN client for tests, made of covtrack's own VRPN wire code: it connects over TCP,
// or asks the server over UDP to call it back (what VRPN's clients do by default), then
// handshakes, pings "Tracker0" and collects the reports by sensor.
#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <chrono>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "covtrack/vrpn/message_names.hpp"
#include "covtrack/vrpn/session.hpp"
#include "covtrack/vrpn/socket.hpp"
#include "covtrack/vrpn/system_messages.hpp"
#include "covtrack/vrpn/tracker_report.hpp"

namespace covtrack::test {

using SteadyClock = std::chrono::steady_clock;

inline SteadyClock::time_point after_s(double seconds) {
  return SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(seconds));
}

// A TCP connection to 127.0.0.1:port, retried until the server listens or `seconds` pass.
inline vrpn::Socket connect_when_listening(int port, double seconds) {
  const auto to = vrpn::ipv4_address(in_addr{htonl(INADDR_LOOPBACK)}, port);
  for (const auto end = after_s(seconds); SteadyClock::now() < end;) {
    auto s = vrpn::connect_tcp(to, 1.0, {});
    if (s) return std::move(*s);
    pollfd none{-1, 0, 0};
    ::poll(&none, 0, 20);  // the daemon is starting: try again shortly
  }
  return {};
}

struct ReceivedReport {
  vrpn::TrackerReport report;
  std::int64_t time_us = 0;     // the header's: the measurement time
  std::int64_t arrival_us = 0;  // this host's clock when it was read
  bool by_udp = false;
};

class VrpnTestClient {
 public:
  explicit VrpnTestClient(std::string tracker = "Tracker0")
      : tracker_(std::move(tracker)),
        session_({tracker_}, {std::string(vrpn::kTrackerPosQuat), std::string(vrpn::kPing), std::string(vrpn::kPong)}) {}

  // Straight over TCP ("Tracker0@tcp://host:port" in VRPN's terms).
  // `receive_buffer` > 0: a small socket buffer, for a client that stops reading.
  bool connect_tcp(int port, double seconds = 10, int receive_buffer = 0) {
    tcp_ = connect_when_listening(port, seconds);
    if (tcp_ && receive_buffer > 0) setsockopt(tcp_.fd(), SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    return static_cast<bool>(tcp_);
  }

  // Sends `bytes` as they are, and from then on nothing of the session's: a client that
  // does not speak VRPN, or speaks it wrongly.
  bool send_raw(const std::vector<std::uint8_t>& bytes) {
    speaks_vrpn_ = false;
    return tcp_ && vrpn::send_all(tcp_, bytes, 2.0);
  }

  // VRPN's default: listen on a TCP port, send "<host> <port>" and a NUL to the server's
  // UDP port until it connects to us; then offer a UDP port for the reports.
  bool connect_by_udp_request(int server_port, double seconds = 10) {
    auto listener = vrpn::listen_tcp("127.0.0.1", 0);
    auto udp_in = vrpn::bind_udp("127.0.0.1", 0);
    auto lob = vrpn::connect_udp(vrpn::ipv4_address(in_addr{htonl(INADDR_LOOPBACK)}, server_port));
    if (!listener || !udp_in || !lob) return false;
    udp_ = std::move(*udp_in);
    const std::string request = "127.0.0.1 " + std::to_string(local_port(*listener)) + std::string(1, '\0');
    for (const auto end = after_s(seconds); SteadyClock::now() < end && !tcp_;) {
      ::send(lob->fd(), request.data(), request.size(), 0);
      pollfd p{listener->fd(), POLLIN, 0};
      if (::poll(&p, 1, 500) > 0) tcp_ = vrpn::Socket(::accept4(listener->fd(), nullptr, nullptr, SOCK_NONBLOCK));
    }
    wants_udp_ = true;
    return static_cast<bool>(tcp_);
  }

  // Reads until `done` holds or `seconds` pass; false on a timeout or a closed connection.
  bool run_until(const std::function<bool()>& done, double seconds) {
    for (const auto end = after_s(seconds); SteadyClock::now() < end;) {
      if (done()) return true;
      if (!step(20)) return done();
    }
    return done();
  }

  // Waits until the server closes the connection; false if it is still open after `seconds`.
  bool closed_by_server_within(double seconds) {
    for (const auto end = after_s(seconds); SteadyClock::now() < end;)
      if (!step(20)) return true;
    return false;
  }

  const vrpn::Session& session() const { return session_; }
  std::map<std::int32_t, std::vector<ReceivedReport>> reports;  // by sensor
  int pongs = 0;
  std::string error;  // why the connection ended

 private:
  static int local_port(const vrpn::Socket& s) {
    sockaddr_in a{};
    socklen_t size = sizeof a;
    getsockname(s.fd(), reinterpret_cast<sockaddr*>(&a), &size);
    return ntohs(a.sin_port);
  }

  // One poll: false once the connection is closed or broken.
  bool step(int timeout_ms) {
    if (!tcp_) return false;
    if (speaks_vrpn_ && session_.has_output() && !vrpn::send_all(tcp_, session_.take_output(), 2.0)) return false;
    std::array<pollfd, 2> p{pollfd{tcp_.fd(), POLLIN, 0}, pollfd{udp_ ? udp_.fd() : -1, POLLIN, 0}};
    if (::poll(p.data(), p.size(), timeout_ms) <= 0) return true;
    std::array<std::uint8_t, 65536> buffer{};
    if (p[1].revents & POLLIN) {
      const ssize_t n = ::recv(udp_.fd(), buffer.data(), buffer.size(), 0);
      if (n > 0)
        if (auto m = session_.receive_datagram(std::span(buffer.data(), static_cast<std::size_t>(n)))) take(*m, true);
    }
    if (!(p[0].revents & (POLLIN | POLLHUP | POLLERR))) return true;
    const ssize_t n = ::recv(tcp_.fd(), buffer.data(), buffer.size(), 0);
    if (n <= 0) {
      error = n == 0 ? "closed" : "broken";
      tcp_ = {};
      return false;
    }
    const bool was_ready = session_.ready();
    auto m = session_.receive(std::span(buffer.data(), static_cast<std::size_t>(n)), 0);
    if (!m) {
      error = m.error().message;
      tcp_ = {};
      return false;
    }
    if (!was_ready && session_.ready()) {
      session_.send(tracker_, vrpn::kPing, 0, {});
      if (wants_udp_)
        session_.describe_udp("127.0.0.1", local_port(udp_), 0);
    }
    take(*m, false);
    return true;
  }

  void take(const std::vector<vrpn::NamedMessage>& messages, bool by_udp) {
    for (const auto& m : messages) {
      if (m.sender != tracker_) continue;
      if (m.type == vrpn::kPong) ++pongs;
      if (m.type != vrpn::kTrackerPosQuat) continue;
      const auto arrival = std::chrono::duration_cast<std::chrono::microseconds>(
                               std::chrono::system_clock::now().time_since_epoch())
                               .count();
      if (auto r = vrpn::decode_pos_quat(m.payload)) reports[r->sensor].push_back({*r, m.time_us, arrival, by_udp});
    }
  }

  std::string tracker_;
  vrpn::Session session_;
  vrpn::Socket tcp_, udp_;
  bool wants_udp_ = false;
  bool speaks_vrpn_ = true;
};

}  // namespace covtrack::test
