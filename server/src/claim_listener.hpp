#pragma once
// What a daemon hears of other daemons on a udpm:// group: heartbeats and claims
// (covtrack/status/*, covtrack/claim/*), and nothing else.
//
// Why not an LCM subscription: every socket on the group receives every datagram, the
// daemon's own poses included. Through LCM that is one wake-up and copy per pose (at
// 10 sensors x 1 kHz it more than doubled the daemon's CPU). Here a socket filter in the
// kernel (classic BPF) lets through only small LCM messages whose channel starts with
// one of the two prefixes; heartbeats and claims are never fragmented.
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "covtrack/protocol/result.hpp"

namespace covtrack::server {

class ClaimListener {
 public:
  // Joins the group of a udpm:// URL.
  static Result<std::unique_ptr<ClaimListener>> open(const std::string& url);
  ~ClaimListener();
  ClaimListener(const ClaimListener&) = delete;
  ClaimListener& operator=(const ClaimListener&) = delete;

  struct Message {
    std::string channel;
    std::vector<std::byte> bytes;
  };
  // The next message, waiting at most `timeout_ms`; nothing on timeout.
  std::optional<Message> receive(int timeout_ms);

 private:
  explicit ClaimListener(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace covtrack::server
