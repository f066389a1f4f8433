#pragma once
// Feedback reports that would move the train where it cannot go are confirmed before
// they are believed. An XpressNet frame is checked by one XOR byte, so one random frame
// in 256 passes it: on a noisy line a forged broadcast that names a far section, or
// clears the occupied one, turns up now and then, and believed at once it would put the
// train somewhere it is not, reported with confidence. Such a change is held, the
// module's nibble is asked for again, and it is applied only when the answer agrees;
// an answer that repeats the old value drops it as noise. Changes the train can make
// (crossing ahead, staying, backing up if it may) are applied at once: confirming them
// would delay every crossing by a round trip. Pure: times are passed in.
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "dead_reckoning.hpp"
#include "feedback_state.hpp"
#include "xpressnet_messages.hpp"

namespace covtrack::lenz {

class FeedbackConfirmation {
 public:
  struct Outcome {
    bool changed = false;                 // the believed inputs changed: re-run the reckoner
    std::vector<FeedbackRequest> ask;     // nibbles to request (held changes)
    std::vector<std::string> dropped;     // held changes that proved to be noise, one line each
  };

  // `timeout_s`: a held change not confirmed by then is dropped.
  FeedbackConfirmation(const TrackLayout& layout, double timeout_s) : layout_(layout), timeout_s_(timeout_s) {}

  Outcome apply(const Feedback& feedback, const DeadReckoner& reckoner, double t_s);
  // Drops held changes older than the timeout.
  Outcome expire(double t_s);
  const FeedbackState& state() const { return state_; }
  std::size_t held() const { return held_.size(); }
  void reset();

 private:
  using Nibble = std::pair<std::uint8_t, bool>;  // wire address, upper nibble
  struct Held { std::uint8_t inputs = 0; double since_s = 0; };

  FeedbackState state_;
  const TrackLayout& layout_;
  double timeout_s_;
  std::map<Nibble, Held> held_;
};

}  // namespace covtrack::lenz
