#pragma once
// Refuses authenticated messages that were seen before or are too old: what a receiver
// with the key checks after the MAC (docs/authentication.md, "Replays").
//
// Per channel and sender instance it keeps the highest counter accepted; a message whose
// counter is not above it is a replay. A sender instance it never heard from (the client
// started later, or the daemon is a new one) starts a new record, so a message captured
// earlier from an instance the receiver never saw would pass that test: the sender's
// clock in the trailer bounds it, as a message sent more than max_age_s ago (or that far
// in the future) is refused too. Only authenticated messages reach it, so its memory grows
// with real channels and senders only; an instance silent for max_age_s is forgotten,
// since every message it ever sent would now be refused by its time anyway.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "covtrack/protocol/message_auth.hpp"

namespace covtrack {

class ReplayGuard {
 public:
  explicit ReplayGuard(double max_age_s) : max_age_us_(static_cast<std::int64_t>(max_age_s * 1e6)) {}

  // Nothing when the message is fresh (and records it); otherwise why it is refused.
  std::optional<std::string> check(std::string_view channel, const AuthTrailer& trailer, std::int64_t now_us);

 private:
  struct Seen {
    std::uint64_t counter = 0;
    std::int64_t sent_us = 0;
  };
  std::int64_t max_age_us_;
  std::map<std::string, std::map<std::uint64_t, Seen>, std::less<>> channels_;  // by channel, then instance
};

}  // namespace covtrack
