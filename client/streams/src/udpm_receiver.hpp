#pragma once
// Receives LCM's udpm:// traffic on a multicast socket read by the caller's own thread:
// no receive thread, no queue and no hand-off between threads (LCM's path has all three),
// datagrams read in batches (recvmmsg), decoded and reassembled by protocol/lcm_datagram
// and lcm_reassembly, and handed to the caller as they complete. Any LCM sender reaches
// it: short messages, fragmented ones and the URL's options are LCM's.
//
// The socket is bound to the group's address, not to every address as LCM binds: only
// datagrams sent to this group arrive, even when another group on the same port is
// joined on the host (with LCM the two cross-talk).
#include <netinet/in.h>
#include <sys/socket.h>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "covtrack/client/receive_buffer.hpp"
#include "covtrack/protocol/lcm_datagram.hpp"
#include "covtrack/protocol/lcm_reassembly.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::client {

class UdpmReceiver {
 public:
  // 4 MiB, which the kernel counts as 8 MiB: about 6,500 pose datagrams (each costs
  // ~1.3 KiB of buffer), 130 ms of a 50 kHz aggregate stream.
  static constexpr int kDefaultReceiveBufferBytes = 4 << 20;

  class Handler {
   public:
    virtual bool wants(std::string_view channel) = 0;  // asked before a message is kept
    virtual void on_message(std::string_view channel, std::span<const std::byte> payload) = 0;
    // A datagram that is not LCM's format, or a fragment that cannot belong; `from` is
    // the sender's address and port.
    virtual void on_malformed(const std::string& from, const lcm_wire::DatagramRejection& why) = 0;

   protected:
    ~Handler() = default;
  };

  // Opens and joins the group of a udpm:// URL (see parse_udpm_url).
  static Result<std::unique_ptr<UdpmReceiver>> open(const std::string& url);
  ~UdpmReceiver();
  UdpmReceiver(const UdpmReceiver&) = delete;
  UdpmReceiver& operator=(const UdpmReceiver&) = delete;

  int fd() const { return fd_; }  // readable when a datagram waits (poll it)
  const ReceiveBufferSize& receive_buffer() const { return buffer_; }

  // Reads what the socket holds, without waiting, in at most `max_batches` batches, and
  // hands each complete message to `handler`. Returns the number of datagrams read.
  int read_available(Handler& handler, int max_batches);

  std::int64_t abandoned() const { return reassembler_.abandoned(); }  // fragmented messages given up

 private:
  explicit UdpmReceiver(int fd);
  void handle(Handler& handler, std::span<const std::byte> datagram, const sockaddr_in& from, std::int64_t now);

  int fd_ = -1;
  ReceiveBufferSize buffer_;
  std::vector<std::byte> storage_;  // one 64 KiB slot per datagram of a batch
  std::vector<iovec> slots_;
  std::vector<sockaddr_in> senders_;
  std::vector<mmsghdr> headers_;
  lcm_wire::Reassembler reassembler_;
};

}  // namespace covtrack::client
