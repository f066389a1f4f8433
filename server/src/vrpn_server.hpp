#pragma once
// covtrackd as a VRPN server (docs/vrpn.md): the streams [vrpn_server] names are served
// as VRPN trackers ("Tracker0@host"), each stream one sensor, to any number of VRPN
// clients. It runs on its own thread: the publish path only hands it a pose (a short
// lock, never a wait), and a client that does not read or sends what no VRPN peer sends
// is dropped with a logged reason, so no client can stall or crash the daemon.
#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "covtrack/devices/driver.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/vrpn/socket.hpp"
#include "covtrack/vrpn/tracker_report.hpp"
#include "vrpn_client_link.hpp"
#include "vrpn_server_config.hpp"

namespace covtrack::server {

class VrpnServer {
 public:
  // Binds the TCP port (and the UDP port of the same number); an error names the address.
  static Result<std::unique_ptr<VrpnServer>> open(const VrpnServerConfig& config);
  ~VrpnServer();  // stops and joins

  void start();
  // A pose as published on LCM; served if its stream is one of a tracker's. Thread-safe
  // and non-blocking. LOST poses are not sent (VRPN has no status: a client keeps the
  // last pose, as it does when a VRPN tracker stops reporting).
  void offer(const std::string& device, const PoseSample& sample);

 private:
  struct Route {
    std::size_t tracker;
    std::int32_t sensor;
  };
  struct Report {
    std::size_t tracker;
    vrpn::TrackerReport report;
    std::int64_t time_us;
  };

  explicit VrpnServer(const VrpnServerConfig& config);
  void serve(std::stop_token stop);
  void accept_clients();
  void answer_connection_requests();
  void send_reports();
  void add_client(vrpn::Socket socket, const sockaddr_in& peer, VrpnClientLink::Origin origin);
  // Logs why (a warning, unless the client just left) and closes the connection.
  void drop(std::size_t index, const std::string& reason);

  VrpnServerConfig config_;
  std::vector<std::string> tracker_names_;
  std::unordered_map<std::string, std::vector<Route>> routes_;  // "device/sensor"
  vrpn::Socket listen_, udp_, wake_;

  std::mutex mutex_;  // guards the queue and the frame warnings
  std::deque<Report> queue_;
  std::set<std::string> warned_frames_;
  std::atomic<std::uint64_t> queue_drops_{0};

  std::vector<std::unique_ptr<VrpnClientLink>> clients_;  // the server thread's only
  std::jthread thread_;
};

}  // namespace covtrack::server
