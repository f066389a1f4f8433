#include "covtrack/vrpn/socket.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <thread>

#include <fmt/format.h>

namespace covtrack::vrpn {
namespace {
using Clock = std::chrono::steady_clock;
constexpr int kPollSliceMs = 20;  // how often waits look at a stop request

std::string errno_text(int error) { return std::strerror(error); }

Result<Socket> new_socket(int type) {
  Socket s(::socket(AF_INET, type | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (!s) return fail(fmt::format("cannot create a socket: {}", errno_text(errno)));
  return s;
}

Result<sockaddr_in> local_address(const std::string& address, int port) {
  in_addr host{};
  if (inet_pton(AF_INET, address.c_str(), &host) != 1)
    return fail(fmt::format("'{}' is no IPv4 address", address));
  return ipv4_address(host, port);
}

Result<Socket> bound(int type, const std::string& address, int port) {
  auto where = local_address(address, port);
  if (!where) return std::unexpected(where.error());
  auto s = new_socket(type);
  if (!s) return s;
  const int on = 1;
  // A restarted daemon must get its port back at once, not after TIME_WAIT.
  setsockopt(s->fd(), SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  if (::bind(s->fd(), reinterpret_cast<const sockaddr*>(&*where), sizeof *where) != 0)
    return fail(fmt::format("cannot bind {} {}: {}", type == SOCK_STREAM ? "TCP" : "UDP", to_string(*where),
                            errno_text(errno)));
  return s;
}

// Waits for `events` on the socket; false at the deadline or a stop request.
bool wait_for(const Socket& s, short events, Clock::time_point deadline, std::stop_token stop) {
  pollfd p{s.fd(), events, 0};
  while (!stop.stop_requested() && Clock::now() < deadline)
    if (::poll(&p, 1, kPollSliceMs) > 0) return true;
  return false;
}

Clock::time_point after(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}
}  // namespace

Socket& Socket::operator=(Socket&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

Socket::~Socket() {
  if (fd_ >= 0) ::close(fd_);
}

std::string to_string(const sockaddr_in& a) {
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &a.sin_addr, text, sizeof text);
  return fmt::format("{}:{}", text, ntohs(a.sin_port));
}

sockaddr_in ipv4_address(in_addr host, int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr = host;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  return a;
}

Result<in_addr> resolve_ipv4(const std::string& host, double timeout_s, std::stop_token stop) {
  in_addr out{};
  if (inet_pton(AF_INET, host.c_str(), &out) == 1) return out;
  struct Lookup {
    std::mutex m;
    std::condition_variable cv;
    std::optional<Result<in_addr>> result;
  };
  auto lookup = std::make_shared<Lookup>();
  std::thread([lookup, host] {
    addrinfo hints{};
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* list = nullptr;
    const int rc = getaddrinfo(host.c_str(), nullptr, &hints, &list);
    Result<in_addr> r = rc != 0 || !list
                            ? Result<in_addr>(fail(fmt::format("cannot resolve '{}': {}", host, gai_strerror(rc))))
                            : Result<in_addr>(reinterpret_cast<const sockaddr_in*>(list->ai_addr)->sin_addr);
    if (list) freeaddrinfo(list);
    std::lock_guard lock(lookup->m);
    lookup->result = std::move(r);
    lookup->cv.notify_all();
  }).detach();
  std::unique_lock lock(lookup->m);
  const auto deadline = after(timeout_s);
  while (!lookup->result && !stop.stop_requested() && Clock::now() < deadline)
    lookup->cv.wait_for(lock, std::chrono::milliseconds(kPollSliceMs));
  if (lookup->result) return *lookup->result;
  return fail(fmt::format("cannot resolve '{}' within {:.1f} s", host, timeout_s));
}

Result<Socket> start_connect_tcp(const sockaddr_in& to) {
  auto s = new_socket(SOCK_STREAM);
  if (!s) return s;
  const int on = 1;
  setsockopt(s->fd(), IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
  if (::connect(s->fd(), reinterpret_cast<const sockaddr*>(&to), sizeof to) != 0 && errno != EINPROGRESS)
    return fail(fmt::format("cannot connect to {}: {}", to_string(to), errno_text(errno)));
  return s;
}

Result<void> finish_connect(const Socket& s, const sockaddr_in& to) {
  int error = 0;
  socklen_t size = sizeof error;
  if (getsockopt(s.fd(), SOL_SOCKET, SO_ERROR, &error, &size) != 0) error = errno;
  if (error != 0) return fail(fmt::format("cannot connect to {}: {}", to_string(to), errno_text(error)));
  return {};
}

Result<Socket> connect_tcp(const sockaddr_in& to, double timeout_s, std::stop_token stop) {
  auto s = start_connect_tcp(to);
  if (!s) return s;
  if (!wait_for(*s, POLLOUT, after(timeout_s), stop)) {
    if (stop.stop_requested()) return fail("stopped while connecting to " + to_string(to));
    return fail(fmt::format("no answer from {} within {:.1f} s", to_string(to), timeout_s));
  }
  if (auto done = finish_connect(*s, to); !done) return std::unexpected(done.error());
  return s;
}

Result<Socket> listen_tcp(const std::string& address, int port) {
  auto s = bound(SOCK_STREAM, address, port);
  if (!s) return s;
  if (::listen(s->fd(), 16) != 0)
    return fail(fmt::format("cannot listen on TCP {}:{}: {}", address, port, errno_text(errno)));
  return s;
}

Result<Socket> bind_udp(const std::string& address, int port) { return bound(SOCK_DGRAM, address, port); }

Result<Socket> connect_udp(const sockaddr_in& to) {
  auto s = new_socket(SOCK_DGRAM);
  if (!s) return s;
  if (::connect(s->fd(), reinterpret_cast<const sockaddr*>(&to), sizeof to) != 0)
    return fail(fmt::format("cannot address UDP to {}: {}", to_string(to), errno_text(errno)));
  return s;
}

Result<void> send_all(const Socket& s, std::span<const std::uint8_t> data, double timeout_s) {
  const auto deadline = after(timeout_s);
  while (!data.empty()) {
    const ssize_t n = ::send(s.fd(), data.data(), data.size(), MSG_NOSIGNAL);
    if (n > 0) {
      data = data.subspan(static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
      return fail(fmt::format("send failed: {}", errno_text(errno)));
    if (!wait_for(s, POLLOUT, deadline, {})) return fail(fmt::format("send blocked for {:.1f} s", timeout_s));
  }
  return {};
}

}  // namespace covtrack::vrpn
