#include "udpm_receiver.hpp"

#include <arpa/inet.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/lcm_url.hpp"

namespace covtrack::client {
namespace {
constexpr std::size_t kBatch = 32;                              // datagrams per recvmmsg
constexpr std::size_t kSlotBytes = lcm_wire::kMaxDatagramBytes + 1;  // any UDP datagram fits

std::string address_text(const sockaddr_in& a) {
  char text[INET_ADDRSTRLEN] = "?";
  ::inet_ntop(AF_INET, &a.sin_addr, text, sizeof text);
  return fmt::format("{}:{}", text, ntohs(a.sin_port));
}

long rmem_max() {
  long v = -1;
  std::ifstream("/proc/sys/net/core/rmem_max") >> v;
  return v;
}

// Asks for `requested` bytes; Linux grants double what it sets, and sets at most
// net.core.rmem_max unless the process may override it.
ReceiveBufferSize size_receive_buffer(int fd, int requested) {
  ReceiveBufferSize size;
  size.requested = requested;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &requested, sizeof requested);
  socklen_t len = sizeof size.granted;
  ::getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size.granted, &len);
  if (size.granted / 2 < requested)
    size.note = fmt::format(
        "the socket receive buffer is {} bytes, not the {} asked for: net.core.rmem_max ({}) caps it, and "
        "messages may be lost in bursts. Raise the cap: sudo sysctl -w net.core.rmem_max={}",
        size.granted / 2, requested, rmem_max(), requested);
  return size;
}

}  // namespace

UdpmReceiver::UdpmReceiver(int fd)
    : fd_(fd), storage_(kBatch * kSlotBytes), slots_(kBatch), senders_(kBatch), headers_(kBatch) {
  for (std::size_t i = 0; i < kBatch; ++i) {
    slots_[i] = {storage_.data() + i * kSlotBytes, kSlotBytes};
    headers_[i].msg_hdr.msg_iov = &slots_[i];
    headers_[i].msg_hdr.msg_iovlen = 1;
    headers_[i].msg_hdr.msg_name = &senders_[i];
  }
}

UdpmReceiver::~UdpmReceiver() {
  if (fd_ >= 0) ::close(fd_);
}

Result<std::unique_ptr<UdpmReceiver>> UdpmReceiver::open(const std::string& url) {
  auto parsed = parse_udpm_url(url);
  if (!parsed) return std::unexpected(parsed.error());
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return fail(fmt::format("LCM URL '{}': cannot create a UDP socket: {}", url, std::strerror(errno)));
  std::unique_ptr<UdpmReceiver> receiver(new UdpmReceiver(fd));
  receiver->buffer_ = size_receive_buffer(fd, parsed->recv_buf_size.value_or(kDefaultReceiveBufferBytes));
  const int one = 1;
  ip_mreq membership{};
  membership.imr_multiaddr = parsed->group.sin_addr;
  membership.imr_interface.s_addr = htonl(INADDR_ANY);
  // Shared with every other LCM program on the port (SO_REUSEADDR, as LCM sets it).
  if (::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0 ||
      ::bind(fd, reinterpret_cast<const sockaddr*>(&parsed->group), sizeof parsed->group) != 0)
    return fail(fmt::format("LCM URL '{}': cannot bind to {}: {}", url, address_text(parsed->group),
                            std::strerror(errno)));
  if (::setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &membership, sizeof membership) != 0)
    return fail(fmt::format("LCM URL '{}': cannot join the multicast group: {}", url, std::strerror(errno)));
  return receiver;
}

int UdpmReceiver::read_available(Handler& handler, int max_batches) {
  int total = 0;
  for (int batch = 0; batch < max_batches; ++batch) {
    for (auto& h : headers_) {
      h.msg_hdr.msg_namelen = sizeof(sockaddr_in);
      h.msg_hdr.msg_flags = 0;
    }
    const int n = ::recvmmsg(fd_, headers_.data(), kBatch, MSG_DONTWAIT, nullptr);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // EAGAIN: nothing waits
    const std::int64_t now = now_us();
    reassembler_.expire(now);
    for (int i = 0; i < n; ++i)
      handle(handler, {static_cast<const std::byte*>(slots_[i].iov_base), headers_[i].msg_len}, senders_[i], now);
    total += n;
    if (static_cast<std::size_t>(n) < kBatch) break;  // the socket is drained
  }
  return total;
}

void UdpmReceiver::handle(Handler& handler, std::span<const std::byte> datagram, const sockaddr_in& from,
                          std::int64_t now) {
  auto decoded = lcm_wire::decode_datagram(datagram);
  if (!decoded) return handler.on_malformed(address_text(from), decoded.error());
  if (const auto* m = std::get_if<lcm_wire::ShortMessage>(&*decoded)) {
    if (handler.wants(m->channel)) handler.on_message(m->channel, m->payload);
    return;
  }
  const lcm_wire::Sender sender{ntohl(from.sin_addr.s_addr), ntohs(from.sin_port)};
  auto done = reassembler_.add(sender, std::get<lcm_wire::Fragment>(*decoded), now,
                               [&handler](std::string_view channel) { return handler.wants(channel); });
  if (!done) return handler.on_malformed(address_text(from), done.error());
  if (*done) handler.on_message((*done)->channel, (*done)->payload);
}

}  // namespace covtrack::client
