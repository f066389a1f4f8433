#include "vrpn_client_link.hpp"

#include <arpa/inet.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "covtrack/vrpn/message_names.hpp"

namespace covtrack::server {
namespace {
// Time for a connection and the client's VRPN cookie (VRPN's clients send theirs at once).
constexpr auto kHandshakeTime = std::chrono::seconds(5);
// Bytes read per call; a VRPN client sends little (descriptions, pings).
constexpr std::size_t kReadChunk = 16 * 1024;

std::vector<std::string> our_types() {
  return {std::string(vrpn::kTrackerPosQuat), std::string(vrpn::kPing), std::string(vrpn::kPong)};
}
}  // namespace

VrpnClientLink::VrpnClientLink(vrpn::Socket tcp, const sockaddr_in& peer, Origin origin,
                               const std::vector<std::string>& trackers, std::size_t max_queued_bytes)
    : tcp_(std::move(tcp)),
      address_(peer),
      peer_(vrpn::to_string(peer)),
      origin_(origin),
      connecting_(origin == Origin::CalledBack),
      session_(trackers, our_types()),
      trackers_(trackers),
      max_queued_bytes_(max_queued_bytes) {}

short VrpnClientLink::poll_events() const {
  if (connecting_) return POLLOUT;
  return static_cast<short>(POLLIN | (pending_.empty() && !session_.has_output() ? 0 : POLLOUT));
}

bool VrpnClientLink::handshake_overdue(std::chrono::steady_clock::time_point now) const {
  return !session_.ready() && now - created_ > kHandshakeTime;
}

Result<void> VrpnClientLink::on_events(short revents, std::int64_t now_us) {
  if (connecting_) {
    if (!(revents & (POLLOUT | POLLERR | POLLHUP))) return {};
    if (auto done = vrpn::finish_connect(tcp_, address_); !done) return done;
    connecting_ = false;
    return flush();  // our cookie
  }
  if (revents & (POLLIN | POLLHUP | POLLERR))
    if (auto r = read(now_us); !r) return r;
  return flush();
}

Result<void> VrpnClientLink::read(std::int64_t now_us) {
  std::array<std::uint8_t, kReadChunk> buffer{};
  const ssize_t n = ::recv(tcp_.fd(), buffer.data(), buffer.size(), 0);
  if (n == 0) return fail(std::string(kClosedByClient));
  if (n < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return {};
    return fail(fmt::format("the connection broke: {}", std::strerror(errno)));
  }
  auto messages = session_.receive(std::span(buffer.data(), static_cast<std::size_t>(n)), now_us);
  if (!messages) return fail("malformed VRPN input: " + messages.error().message);
  for (const auto& m : *messages)
    // The client's device object asks whether our device is there; answer as VRPN does.
    if (m.type == vrpn::kPing && std::find(trackers_.begin(), trackers_.end(), m.sender) != trackers_.end())
      session_.send(m.sender, vrpn::kPong, now_us, {});
  if (!udp_ && origin_ == Origin::CalledBack && session_.peer_udp()) open_udp();
  return {};
}

void VrpnClientLink::open_udp() {
  in_addr host{};
  if (inet_pton(AF_INET, session_.peer_udp()->host.c_str(), &host) != 1) {
    // A host name instead of an address: the reports stay on TCP, which always works.
    spdlog::info("vrpn_server: client {} gives UDP host '{}', not an IPv4 address: reports go over TCP", peer_,
                 session_.peer_udp()->host);
    return;
  }
  auto udp = vrpn::connect_udp(vrpn::ipv4_address(host, session_.peer_udp()->port));
  if (!udp) {
    spdlog::warn("vrpn_server: client {}: {}; reports go over TCP", peer_, udp.error().message);
    return;
  }
  udp_ = std::move(*udp);
  spdlog::info("vrpn_server: client {} takes its reports over UDP at {}:{}", peer_, session_.peer_udp()->host,
               session_.peer_udp()->port);
}

Result<void> VrpnClientLink::send_report(const std::string& tracker, const vrpn::TrackerReport& report,
                                         std::int64_t time_us) {
  if (!session_.ready() || connecting_) return {};  // VRPN sends nothing before the handshake either
  if (udp_) {
    const auto datagram = session_.frame_for_udp(tracker, vrpn::kTrackerPosQuat, time_us, vrpn::encode_pos_quat(report));
    // UDP is for what may be lost: a full socket buffer drops the report.
    if (::send(udp_.fd(), datagram.data(), datagram.size(), MSG_DONTWAIT | MSG_NOSIGNAL) < 0) ++udp_drops_;
    return {};
  }
  session_.send(tracker, vrpn::kTrackerPosQuat, time_us, vrpn::encode_pos_quat(report));
  return flush();
}

Result<void> VrpnClientLink::flush() {
  if (session_.has_output()) {
    const auto more = session_.take_output();
    pending_.insert(pending_.end(), more.begin(), more.end());
  }
  if (connecting_) return {};
  while (!pending_.empty()) {
    const ssize_t n = ::send(tcp_.fd(), pending_.data(), pending_.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n > 0) {
      pending_.erase(pending_.begin(), pending_.begin() + n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK)
      return fail(fmt::format("the connection broke: {}", std::strerror(errno)));
    break;
  }
  if (pending_.size() > max_queued_bytes_)
    return fail(fmt::format("the client does not read: {} bytes wait to be sent (vrpn_server.max_queued_bytes = {})",
                            pending_.size(), max_queued_bytes_));
  return {};
}

}  // namespace covtrack::server
