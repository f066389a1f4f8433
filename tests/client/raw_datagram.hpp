#pragma once
// Sends one UDP datagram to a multicast group, as any program could: bytes that LCM
// would never send, for the tests of what a receiver makes of them.
#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstddef>

namespace covtrack::test {

// Whether the whole datagram was sent to group:port.
inline bool send_datagram(const char* group, int port, const void* data, std::size_t size) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return false;
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  ::inet_pton(AF_INET, group, &to.sin_addr);
  const ssize_t n = ::sendto(fd, data, size, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  ::close(fd);
  return n == static_cast<ssize_t>(size);
}

}  // namespace covtrack::test
