#pragma once
// Puts LCM's fragmented messages (lcm_datagram.hpp) back together, within bounds.
//
// An LCM sender sends the fragments of one message in order, before its next message, so
// a receiver keeps at most one partial message per sender (address and port). A partial
// message is given up (counted in abandoned()) when its sender starts another, when it
// has had no fragment for stale_after_us, or when the oldest must make room under the
// bounds. Fragment 0 carries the channel: a fragment of a message whose fragment 0 was
// not received (lost, or refused by `wanted`) is dropped, as LCM does.
#include <cstdint>
#include <expected>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "covtrack/protocol/lcm_datagram.hpp"

namespace covtrack::lcm_wire {

struct ReassemblyLimits {
  std::uint32_t max_message_bytes = 16u << 20;  // a larger message is refused at its fragment 0
  std::size_t max_total_bytes = 64u << 20;      // of all partial messages together
  std::size_t max_partial_messages = 64;        // senders with a message under way
  std::int64_t stale_after_us = 1'000'000;      // a partial message without a new fragment
};

struct Sender {
  std::uint32_t address = 0;  // IPv4, host order
  std::uint16_t port = 0;
  friend bool operator==(const Sender&, const Sender&) = default;
};

struct CompleteMessage {
  std::string channel;
  std::vector<std::byte> payload;
};

class Reassembler {
 public:
  using Wanted = std::function<bool(std::string_view channel)>;

  explicit Reassembler(ReassemblyLimits limits = {});

  // One fragment from `from`, received at `now_us`. Returns the message it completes, if
  // any, or why it was refused. `wanted` is asked at fragment 0 whether to keep the message.
  std::expected<std::optional<CompleteMessage>, DatagramRejection> add(const Sender& from, const Fragment& fragment,
                                                                       std::int64_t now_us, const Wanted& wanted);

  // Gives up the partial messages without a fragment since now_us - stale_after_us.
  void expire(std::int64_t now_us);

  std::int64_t abandoned() const { return abandoned_; }  // partial messages given up
  std::size_t partial_messages() const { return partials_.size(); }
  std::size_t bytes_held() const { return bytes_held_; }

 private:
  struct Partial {
    Sender from;
    std::uint32_t sequence = 0;
    bool ignored = false;  // refused at fragment 0: its other fragments are dropped silently
    std::uint16_t count = 0;
    std::uint16_t received = 0;
    std::uint64_t bytes_received = 0;
    std::vector<bool> have;  // by fragment number
    std::string channel;
    std::vector<std::byte> payload;
    std::int64_t last_us = 0;
  };
  Partial* find(const Sender& from);
  void drop(Partial* p, bool count_as_abandoned);
  Partial& start(const Sender& from, const Fragment& f, std::int64_t now_us, bool ignored);

  ReassemblyLimits limits_;
  std::vector<Partial> partials_;  // few: one per sender with a message under way
  std::size_t bytes_held_ = 0;
  std::int64_t abandoned_ = 0;
};

}  // namespace covtrack::lcm_wire
