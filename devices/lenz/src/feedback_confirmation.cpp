#include "feedback_confirmation.hpp"

#include <fmt/format.h>

namespace covtrack::lenz {
namespace {

std::string describe(std::uint8_t address, bool upper) {
  return fmt::format("feedback module {} inputs {}", address + 1, upper ? "5-8" : "1-4");
}

}  // namespace

FeedbackConfirmation::Outcome FeedbackConfirmation::apply(const Feedback& feedback, const DeadReckoner& reckoner,
                                                          double t_s) {
  Outcome out;
  Feedback fresh;  // pairs not answering a held change
  for (const auto& pair : feedback.pairs) {
    if (!pair.is_feedback_module()) continue;
    const Nibble key{pair.address, pair.upper_nibble()};
    const auto held = held_.find(key);
    if (held == held_.end()) {
      fresh.pairs.push_back(pair);
      continue;
    }
    if (pair.inputs() == held->second.inputs) {  // confirmed: the second report agrees
      out.changed = state_.apply(Feedback{{pair}}) || out.changed;
      held_.erase(held);
      continue;
    }
    // Any other report: the held change was not confirmed (noise); this one is judged
    // afresh, so that a true change arriving meanwhile is not delayed.
    out.dropped.push_back(fmt::format("{}: a change to {:04b} was not confirmed and is dropped (line noise?)",
                                      describe(key.first, key.second), held->second.inputs));
    held_.erase(held);
    fresh.pairs.push_back(pair);
  }
  if (fresh.pairs.empty()) return out;
  FeedbackState trial = state_;
  if (!trial.apply(fresh)) return out;
  const auto occupied = section_occupancy(layout_, trial);
  if (!occupied || reckoner.is_possible_move(*occupied)) {
    state_ = trial;
    out.changed = true;
    return out;
  }
  for (const auto& pair : fresh.pairs) {
    const Nibble key{pair.address, pair.upper_nibble()};
    if (pair.inputs() == state_.nibble(key.first, key.second)) continue;  // unchanged
    held_[key] = {pair.inputs(), t_s};
    out.ask.push_back({key.first, key.second});
  }
  return out;
}

FeedbackConfirmation::Outcome FeedbackConfirmation::expire(double t_s) {
  Outcome out;
  for (auto it = held_.begin(); it != held_.end();) {
    if (t_s - it->second.since_s < timeout_s_) {
      ++it;
      continue;
    }
    out.dropped.push_back(fmt::format("{}: a change to {:04b} was not confirmed within {:.1f} s and is dropped",
                                      describe(it->first.first, it->first.second), it->second.inputs, timeout_s_));
    it = held_.erase(it);
  }
  return out;
}

void FeedbackConfirmation::reset() {
  state_.reset();
  held_.clear();
}

}  // namespace covtrack::lenz
