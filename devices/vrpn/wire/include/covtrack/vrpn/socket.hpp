#pragma once
// The few IPv4 socket operations VRPN needs (it speaks IPv4 only), each with an error
// that names the address, and none that blocks beyond a timeout or a stop request.
#include <netinet/in.h>

#include <cstdint>
#include <span>
#include <stop_token>
#include <string>
#include <utility>

#include "covtrack/protocol/result.hpp"

namespace covtrack::vrpn {

class Socket {
 public:
  Socket() = default;
  explicit Socket(int fd) : fd_(fd) {}
  Socket(Socket&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  Socket& operator=(Socket&& other) noexcept;
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  ~Socket();

  int fd() const { return fd_; }
  explicit operator bool() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

// "1.2.3.4:5678"
std::string to_string(const sockaddr_in& address);
sockaddr_in ipv4_address(in_addr host, int port);

// A dotted address at once; a host name through the resolver, on a helper thread so
// that a stop request or the timeout ends the wait (the lookup then finishes unheard).
Result<in_addr> resolve_ipv4(const std::string& host, double timeout_s, std::stop_token stop);

// A connected, non-blocking TCP socket with TCP_NODELAY (VRPN sets it: reports are small).
Result<Socket> connect_tcp(const sockaddr_in& to, double timeout_s, std::stop_token stop);
// The same, started without waiting: the socket becomes writable when the connection is
// made or has failed; finish_connect says which.
Result<Socket> start_connect_tcp(const sockaddr_in& to);
Result<void> finish_connect(const Socket& socket, const sockaddr_in& to);

// Non-blocking listening sockets; `address` is a dotted IPv4 address ("0.0.0.0": all).
Result<Socket> listen_tcp(const std::string& address, int port);
Result<Socket> bind_udp(const std::string& address, int port);
// A non-blocking UDP socket whose datagrams all go to `to`.
Result<Socket> connect_udp(const sockaddr_in& to);

// Writes all of `data` within `timeout_s` (the socket is non-blocking).
Result<void> send_all(const Socket& socket, std::span<const std::uint8_t> data, double timeout_s);

}  // namespace covtrack::vrpn
