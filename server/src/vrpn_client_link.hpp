#pragma once
// One VRPN client of covtrackd's VRPN server: its TCP socket, its protocol session, the
// bytes waiting to be sent and, for a client that asked for them, the UDP socket its
// reports go to. Never blocks: what the socket does not take waits, up to a limit past
// which the client is dropped (a client that does not read must not hold the daemon).
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "covtrack/protocol/result.hpp"
#include "covtrack/vrpn/session.hpp"
#include "covtrack/vrpn/socket.hpp"
#include "covtrack/vrpn/tracker_report.hpp"

namespace covtrack::server {

class VrpnClientLink {
 public:
  enum class Origin {
    Accepted,   // the client connected to our TCP port: TCP only, as VRPN does then
    CalledBack  // we connected to the client after its UDP request: UDP reports allowed
  };
  // `trackers`: the senders this server describes. A CalledBack socket may still be
  // connecting.
  VrpnClientLink(vrpn::Socket tcp, const sockaddr_in& peer, Origin origin, const std::vector<std::string>& trackers,
                 std::size_t max_queued_bytes);

  // The reason on_events gives when the client ends the connection itself.
  static constexpr std::string_view kClosedByClient = "the client closed the connection";

  int fd() const { return tcp_.fd(); }
  const std::string& peer() const { return peer_; }
  short poll_events() const;
  // Handles what poll reported for fd(). An error is the reason to drop the client.
  Result<void> on_events(short revents, std::int64_t now_us);
  // Queues (TCP) or sends (UDP) one report; an error is the reason to drop the client.
  Result<void> send_report(const std::string& tracker, const vrpn::TrackerReport& report, std::int64_t time_us);
  // The connection and the client's cookie have not come within the handshake time.
  bool handshake_overdue(std::chrono::steady_clock::time_point now) const;
  std::uint64_t udp_drops() const { return udp_drops_; }

 private:
  Result<void> read(std::int64_t now_us);
  void open_udp();
  Result<void> flush();

  vrpn::Socket tcp_, udp_;
  sockaddr_in address_;
  std::string peer_;  // "address:port", for the log
  Origin origin_;
  bool connecting_;
  vrpn::Session session_;
  std::vector<std::string> trackers_;
  std::vector<std::uint8_t> pending_;
  std::size_t max_queued_bytes_;
  std::chrono::steady_clock::time_point created_ = std::chrono::steady_clock::now();
  std::uint64_t udp_drops_ = 0;
};

}  // namespace covtrack::server
