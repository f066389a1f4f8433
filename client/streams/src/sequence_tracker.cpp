#include "covtrack/client/sequence_tracker.hpp"

namespace covtrack::client {

bool SequenceTracker::ahead_within_window(std::int64_t from, std::int64_t to) const {
  if (to <= from) return false;
  // The difference of two int64 always fits in a uint64.
  const std::uint64_t ahead = static_cast<std::uint64_t>(to) - static_cast<std::uint64_t>(from);
  return ahead <= static_cast<std::uint64_t>(window_);
}

SequenceTracker::Result SequenceTracker::classify(std::int64_t sequence) {
  if (!started_) {
    started_ = true;
    last_ = sequence;
    return {Verdict::First};
  }
  if (ahead_within_window(last_, sequence)) {
    const std::int64_t lost = sequence - last_ - 1;
    last_ = sequence;
    candidate_run_ = 0;  // the stream's track spoke: a second track's run is broken
    return {Verdict::InOrder, lost};
  }
  if (candidate_ && ahead_within_window(candidate_last_, sequence)) {
    candidate_last_ = sequence;
    if (++candidate_run_ >= kConfirm) {
      last_ = sequence;
      candidate_ = false;
      candidate_run_ = 0;
      return {Verdict::Restart};
    }
    return {Verdict::Foreign};
  }
  candidate_ = true;  // a new second track starts here
  candidate_last_ = sequence;
  candidate_run_ = 1;
  return {Verdict::Foreign};
}

}  // namespace covtrack::client
