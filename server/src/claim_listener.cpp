#include "claim_listener.hpp"

#include <arpa/inet.h>
#include <linux/filter.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "covtrack/protocol/lcm_datagram.hpp"
#include "covtrack/protocol/lcm_url.hpp"

namespace covtrack::server {
namespace {

// A small LCM message: "LC02", a 4-byte sequence number, the channel and its NUL, then
// the payload. The filter sees the datagram from its UDP header on: payload at 8.
constexpr std::uint32_t kUdpHeader = 8;
constexpr std::uint32_t kChannelAt = kUdpHeader + 8;

// Big-endian words of the text, as BPF loads them.
constexpr std::uint32_t word(const char (&t)[5]) {
  return (std::uint32_t(std::uint8_t(t[0])) << 24) | (std::uint32_t(std::uint8_t(t[1])) << 16) |
         (std::uint32_t(std::uint8_t(t[2])) << 8) | std::uint32_t(std::uint8_t(t[3]));
}

// Accepts "LC02" messages on covtrack/status/... and covtrack/claim/...; drops the rest.
// Jumps count the instructions to skip: (jt, jf).
const sock_filter kFilter[] = {
    BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kUdpHeader),              // 0
    BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, word("LC02"), 0, 13),    // 1 -> drop
    BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kChannelAt),              // 2
    BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, word("covt"), 0, 11),    // 3
    BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kChannelAt + 4),          // 4
    BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, word("rack"), 0, 9),     // 5
    BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kChannelAt + 8),          // 6
    BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, word("/sta"), 0, 2),     // 7 -> 10
    BPF_STMT(BPF_LD | BPF_W | BPF_ABS, kChannelAt + 12),         // 8
    BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, word("tus/"), 6, 5),     // 9 -> accept, drop
    BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, word("/cla"), 0, 4),     // 10 -> drop
    BPF_STMT(BPF_LD | BPF_H | BPF_ABS, kChannelAt + 12),         // 11
    BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, 0x696d /* "im" */, 0, 2),  // 12 -> drop
    BPF_STMT(BPF_LD | BPF_B | BPF_ABS, kChannelAt + 14),         // 13
    BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, '/', 1, 0),              // 14 -> accept
    BPF_STMT(BPF_RET | BPF_K, 0),                                // 15 drop
    BPF_STMT(BPF_RET | BPF_K, 0xffff),                           // 16 accept
};

}  // namespace

Result<std::unique_ptr<ClaimListener>> ClaimListener::open(const std::string& url) {
  auto group = parse_udpm(url);
  if (!group) return std::unexpected(group.error());
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return fail(fmt::format("claims: socket: {}", std::strerror(errno)));
  std::unique_ptr<ClaimListener> listener(new ClaimListener(fd));
  const int one = 1;
  ip_mreq membership{};
  membership.imr_multiaddr = group->sin_addr;
  membership.imr_interface.s_addr = htonl(INADDR_ANY);
  const sock_fprog program{static_cast<unsigned short>(std::size(kFilter)), const_cast<sock_filter*>(kFilter)};
  // The filter before the bind: no datagram gets in unfiltered. Bound to the group's
  // address, not to any: another group on the same port (another lab's daemons) stays out.
  if (::setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &program, sizeof program) != 0 ||
      ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0 ||
      ::bind(fd, reinterpret_cast<const sockaddr*>(&*group), sizeof *group) != 0 ||
      ::setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof membership) != 0)
    return fail(fmt::format("claims: cannot listen on {}: {}", url, std::strerror(errno)));
  return listener;
}

ClaimListener::~ClaimListener() {
  if (fd_ >= 0) ::close(fd_);
}

std::optional<ClaimListener::Message> ClaimListener::receive(int timeout_ms) {
  pollfd p{fd_, POLLIN, 0};
  if (::poll(&p, 1, timeout_ms) <= 0) return std::nullopt;
  std::byte datagram[lcm_wire::kMaxDatagramBytes + 1];
  const ssize_t n = ::recv(fd_, datagram, sizeof datagram, MSG_DONTWAIT);
  if (n <= 0) return std::nullopt;
  const auto decoded = lcm_wire::decode_datagram({datagram, static_cast<std::size_t>(n)});
  const auto* m = decoded ? std::get_if<lcm_wire::ShortMessage>(&*decoded) : nullptr;
  if (!m) return std::nullopt;  // the filter lets only short messages through
  return Message{std::string(m->channel), std::vector<std::byte>(m->payload.begin(), m->payload.end())};
}

}  // namespace covtrack::server
