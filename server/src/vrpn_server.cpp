#include "vrpn_server.hpp"

#include <arpa/inet.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <optional>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "covtrack/protocol/clock.hpp"

namespace covtrack::server {
namespace {
constexpr int kPollMs = 50;  // a stop is noticed within this
// Reports waiting for the server thread; beyond this the oldest go (it has fallen behind).
constexpr std::size_t kMaxQueuedReports = 4096;
// The kernel's share of a client's unsent bytes. Fixed (Linux would otherwise grow it to
// megabytes): reports stuck there are seconds old before a slow client is noticed.
constexpr int kSocketSendBuffer = 64 * 1024;

// VRPN's connection request: "<host> <port>" and a NUL, asking the server to connect to
// the client's TCP port. Only the port is used: the connection goes to the address the
// datagram came from, so a request cannot aim the daemon at a third host.
std::optional<int> requested_port(std::string_view text) {
  const auto end = text.find('\0');
  if (end != std::string_view::npos) text = text.substr(0, end);
  const auto space = text.find(' ');
  if (space == std::string_view::npos || space == 0) return std::nullopt;
  for (char c : text.substr(0, space))
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-') return std::nullopt;
  const std::string_view digits = text.substr(space + 1);
  int port = 0;
  const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
  // VRPN refuses ports below 1024 too (they belong to root's services).
  if (ec != std::errc{} || ptr != digits.data() + digits.size() || port < 1024 || port > 65535) return std::nullopt;
  return port;
}
}  // namespace

Result<std::unique_ptr<VrpnServer>> VrpnServer::open(const VrpnServerConfig& config) {
  std::unique_ptr<VrpnServer> s(new VrpnServer(config));
  auto listen = vrpn::listen_tcp(config.address, config.port);
  if (!listen) return fail("vrpn_server: " + listen.error().message);
  s->listen_ = std::move(*listen);
  if (config.udp) {
    auto udp = vrpn::bind_udp(config.address, config.port);
    if (!udp) return fail("vrpn_server: " + udp.error().message);
    s->udp_ = std::move(*udp);
  }
  s->wake_ = vrpn::Socket(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
  if (!s->wake_) return fail(fmt::format("vrpn_server: cannot create an eventfd: {}", std::strerror(errno)));
  return s;
}

VrpnServer::VrpnServer(const VrpnServerConfig& config) : config_(config) {
  for (std::size_t t = 0; t < config_.trackers.size(); ++t) {
    tracker_names_.push_back(config_.trackers[t].name);
    const auto& streams = config_.trackers[t].streams;
    for (std::size_t i = 0; i < streams.size(); ++i)
      routes_[streams[i]].push_back({t, static_cast<std::int32_t>(i)});
  }
}

VrpnServer::~VrpnServer() {
  thread_.request_stop();
  if (thread_.joinable()) thread_.join();
}

void VrpnServer::start() {
  spdlog::info("vrpn_server: serving {} tracker(s) on {}:{} (TCP{})", config_.trackers.size(), config_.address,
               config_.port, config_.udp ? ", and UDP connection requests" : "");
  thread_ = std::jthread([this](std::stop_token stop) { serve(stop); });
}

void VrpnServer::offer(const std::string& device, const PoseSample& sample) {
  const auto route = routes_.find(device + "/" + sample.sensor);
  if (route == routes_.end() || sample.status == TrackingStatus::Lost) return;
  {
    std::lock_guard lock(mutex_);
    for (const Route& r : route->second) {
      const auto& tracker = config_.trackers[r.tracker];
      if (sample.parent_frame != tracker.frame) {
        // The config check saw the device's parent_frame; a driver may still publish
        // some stream in another frame. Mixing frames in one tracker would mislead.
        if (warned_frames_.insert(route->first).second)
          spdlog::warn("vrpn_server: stream '{}' is in frame '{}', tracker '{}' serves frame '{}': not served",
                       route->first, sample.parent_frame, tracker.name, tracker.frame);
        continue;
      }
      if (queue_.size() >= kMaxQueuedReports) {
        queue_.pop_front();
        ++queue_drops_;
      }
      queue_.push_back({r.tracker, vrpn::report_of(r.sensor, sample.T_parent_child), sample.measurement_time_us});
    }
  }
  const std::uint64_t one = 1;
  [[maybe_unused]] const auto n = ::write(wake_.fd(), &one, sizeof one);  // never blocks: non-blocking eventfd
}

void VrpnServer::serve(std::stop_token stop) {
  std::vector<pollfd> fds;
  while (!stop.stop_requested()) {
    fds.clear();
    fds.push_back({wake_.fd(), POLLIN, 0});
    fds.push_back({listen_.fd(), POLLIN, 0});
    fds.push_back({udp_ ? udp_.fd() : -1, POLLIN, 0});
    for (const auto& c : clients_) fds.push_back({c->fd(), c->poll_events(), 0});
    if (::poll(fds.data(), fds.size(), kPollMs) < 0 && errno != EINTR) {
      spdlog::error("vrpn_server: poll failed: {}", std::strerror(errno));
      continue;
    }
    if (fds[0].revents & POLLIN) {
      std::uint64_t count = 0;
      [[maybe_unused]] const auto n = ::read(wake_.fd(), &count, sizeof count);
    }
    // Clients first, by the index poll saw them at; new ones join after.
    const auto now = now_us();
    const auto steady = std::chrono::steady_clock::now();
    for (std::size_t i = clients_.size(); i-- > 0;) {
      const short revents = fds[3 + i].revents;
      if (revents)
        if (auto r = clients_[i]->on_events(revents, now); !r) {
          drop(i, r.error().message);
          continue;
        }
      if (clients_[i]->handshake_overdue(steady)) drop(i, "no VRPN handshake within 5 s");
    }
    send_reports();
    if (fds[1].revents & POLLIN) accept_clients();
    if (fds[2].revents & POLLIN) answer_connection_requests();
  }
  clients_.clear();
}

void VrpnServer::send_reports() {
  std::deque<Report> reports;
  {
    std::lock_guard lock(mutex_);
    reports.swap(queue_);
  }
  if (const auto dropped = queue_drops_.exchange(0))
    spdlog::warn("vrpn_server: fell behind the publishers: {} reports dropped", dropped);
  for (const auto& r : reports)
    for (std::size_t i = clients_.size(); i-- > 0;)
      if (auto sent = clients_[i]->send_report(tracker_names_[r.tracker], r.report, r.time_us); !sent)
        drop(i, sent.error().message);
}

void VrpnServer::accept_clients() {
  for (;;) {
    sockaddr_in peer{};
    socklen_t size = sizeof peer;
    vrpn::Socket s(::accept4(listen_.fd(), reinterpret_cast<sockaddr*>(&peer), &size, SOCK_NONBLOCK | SOCK_CLOEXEC));
    if (!s) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
        spdlog::warn("vrpn_server: accept failed: {}", std::strerror(errno));
      return;
    }
    const int on = 1;
    setsockopt(s.fd(), IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);  // reports are small and time-critical
    add_client(std::move(s), peer, VrpnClientLink::Origin::Accepted);
  }
}

void VrpnServer::answer_connection_requests() {
  std::array<char, 256> text{};
  for (;;) {
    sockaddr_in from{};
    socklen_t size = sizeof from;
    const ssize_t n = ::recvfrom(udp_.fd(), text.data(), text.size(), 0, reinterpret_cast<sockaddr*>(&from), &size);
    if (n < 0) return;
    const auto port = requested_port(std::string_view(text.data(), static_cast<std::size_t>(n)));
    if (!port) {
      spdlog::warn("vrpn_server: ignored a malformed UDP connection request from {}", vrpn::to_string(from));
      continue;
    }
    const sockaddr_in to = vrpn::ipv4_address(from.sin_addr, *port);
    // A VRPN client repeats its request every 2 s until called back: one call is enough.
    bool known = false;
    for (const auto& c : clients_) known = known || c->peer() == vrpn::to_string(to);
    if (known) continue;
    auto socket = vrpn::start_connect_tcp(to);
    if (!socket) {
      spdlog::warn("vrpn_server: cannot call back {}: {}", vrpn::to_string(to), socket.error().message);
      continue;
    }
    add_client(std::move(*socket), to, VrpnClientLink::Origin::CalledBack);
  }
}

void VrpnServer::add_client(vrpn::Socket socket, const sockaddr_in& peer, VrpnClientLink::Origin origin) {
  if (clients_.size() >= static_cast<std::size_t>(config_.max_clients)) {
    spdlog::warn("vrpn_server: refused {}: {} clients already (vrpn_server.max_clients)", vrpn::to_string(peer),
                 clients_.size());
    return;
  }
  setsockopt(socket.fd(), SOL_SOCKET, SO_SNDBUF, &kSocketSendBuffer, sizeof kSocketSendBuffer);
  clients_.push_back(
      std::make_unique<VrpnClientLink>(std::move(socket), peer, origin, tracker_names_, config_.max_queued_bytes));
  spdlog::info("vrpn_server: client {} {}", vrpn::to_string(peer),
               origin == VrpnClientLink::Origin::Accepted ? "connected" : "asked over UDP; calling it back");
}

void VrpnServer::drop(std::size_t index, const std::string& reason) {
  const auto& c = *clients_[index];
  if (reason != VrpnClientLink::kClosedByClient) spdlog::warn("vrpn_server: dropped client {}: {}", c.peer(), reason);
  else spdlog::info("vrpn_server: client {} left: {}", c.peer(), reason);
  clients_.erase(clients_.begin() + static_cast<std::ptrdiff_t>(index));
}

}  // namespace covtrack::server
