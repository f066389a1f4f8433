#include "dead_reckoning.hpp"

#include <algorithm>
#include <cmath>

namespace covtrack::lenz {

DeadReckoner::DeadReckoner(const TrackLayout& layout, DeadReckoningParams params)
    : layout_(layout), params_(params) {}

void DeadReckoner::reset() {
  section_.reset();
  entered_at_s_.reset();
  entry_speed_.reset();
  direction_ = +1;
}

void DeadReckoner::lose() { reset(); }

DeadReckoner::Move DeadReckoner::classify(const std::vector<bool>& occ) const {
  const auto count = std::count(occ.begin(), occ.end(), true);
  const std::size_t here = *section_;
  const std::size_t ahead = direction_ > 0 ? layout_.next(here) : layout_.previous(here);
  const std::size_t behind = direction_ > 0 ? layout_.previous(here) : layout_.next(here);
  // Crossed into the section ahead (the one left may still read occupied for a moment).
  if (occ[ahead] && (count == 1 || (count == 2 && occ[here]))) return Move::Ahead;
  // Still here, possibly with the rear pickups still on the section just left.
  if (occ[here] && (count == 1 || (count == 2 && occ[behind]))) return Move::Stay;
  // Went back into the section behind: only a train that may reverse does that.
  if (layout_.train().reversible && occ[behind] && count == 1) return Move::Behind;
  return Move::Impossible;  // a skipped section, a jump, a move backwards, a vanished train
}

bool DeadReckoner::is_possible_move(const std::vector<bool>& occupied) const {
  return !section_ || classify(occupied) != Move::Impossible;
}

void DeadReckoner::on_occupancy(const std::optional<std::vector<bool>>& occupied, double t_s, double read_late_s) {
  if (!occupied) return lose();
  const auto& occ = *occupied;
  const auto count = std::count(occ.begin(), occ.end(), true);
  if (count == 0) return lose();
  if (section_) {
    const std::size_t here = *section_;
    const double latency_s = params_.crossing_latency_s + std::max(0.0, read_late_s);
    switch (classify(occ)) {
      case Move::Ahead:
        return enter(direction_ > 0 ? layout_.next(here) : layout_.previous(here), direction_, t_s, latency_s);
      case Move::Stay: return;
      case Move::Behind:
        return enter(direction_ > 0 ? layout_.previous(here) : layout_.next(here), -direction_, t_s, latency_s);
      case Move::Impossible: break;
    }
  }
  // First report, or a pattern the train cannot produce from where we thought it was:
  // start again from what is occupied.
  if (section_) ++inconsistencies_;
  reset();
  if (count == 1) section_ = static_cast<std::size_t>(std::find(occ.begin(), occ.end(), true) - occ.begin());
  // Two or more occupied: several candidate sections, no estimate until it clears up.
}

void DeadReckoner::enter(std::size_t section, int direction, double t_s, double latency_s) {
  // Speed at the boundary from the time since the previous crossing, if that was seen:
  // the whole section's length if the train went through it, nothing if it came back.
  if (entered_at_s_)
    entry_speed_ = speed_after(*section_, t_s - *entered_at_s_, entered_latency_s_, latency_s, direction == direction_);
  else
    entry_speed_.reset();
  section_ = section;
  direction_ = direction;
  entered_at_s_ = t_s;
  entered_latency_s_ = latency_s;
}

DeadReckoner::SpeedRange DeadReckoner::speed_after(std::size_t section, double traversal_s, double latency_before_s,
                                                   double latency_after_s, bool same_direction) const {
  const Train& train = layout_.train();
  const double a = train.max_accel_mps2, v_max = train.max_speed_mps;
  const double distance = same_direction ? layout_.sections()[section].length_m : 0.0;
  // Each crossing was detected up to its latency late, so the true time between them is
  // T - latency_after to T + latency_before; both bounds below are monotonic or convex
  // in it, so its two ends suffice.
  const double t_short = std::max(traversal_s - latency_after_s, 1e-3), t_long = traversal_s + latency_before_s;
  // Highest end speed: accelerating all the way. A train that cannot reverse may also
  // have stood and then accelerated, which caps it at sqrt(2 a d).
  const auto highest = [&](double T) {
    const double ramp = distance / T + a * T / 2;
    if (train.reversible || distance / T >= a * T / 2) return ramp;
    return std::sqrt(2 * a * distance);
  };
  // Lowest: braking all the way (it was moving forwards at the crossing, so not below 0).
  const auto lowest = [&](double T) { return std::max(0.0, distance / T - a * T / 2); };
  const double hi = std::min(v_max, std::max(highest(t_short), highest(t_long)));
  const double lo = std::min(lowest(t_short), lowest(t_long));
  return {std::min(lo, hi), hi};
}

double DeadReckoner::min_distance(double v, double t) const {
  const double a = layout_.train().max_accel_mps2;
  if (t <= 0) return 0;
  return v > a * t ? v * t - a * t * t / 2 : v * v / (2 * a);  // braking hardest, then stopped
}

double DeadReckoner::max_distance(double v, double t) const {
  const double a = layout_.train().max_accel_mps2, v_max = layout_.train().max_speed_mps;
  if (t <= 0) return 0;
  const double t_top = std::max(0.0, (v_max - v) / a);  // accelerating hardest, then at v_max
  if (t <= t_top) return v * t + a * t * t / 2;
  return v * t_top + a * t_top * t_top / 2 + v_max * (t - t_top);
}

AlongTrack DeadReckoner::estimate(double t_s, double unseen_s) const {
  AlongTrack out;
  if (!section_) return out;
  const Section& sec = layout_.sections()[*section_];
  const Train& train = layout_.train();
  out.section = *section_;
  out.lo_s = sec.start_s;
  out.hi_s = sec.end_s();
  if (!entered_at_s_) {
    out.state = AlongTrack::State::WholeSection;
    return out;
  }
  out.state = AlongTrack::State::DeadReckoning;
  const SpeedRange v = entry_speed_.value_or(SpeedRange{0, train.max_speed_mps});
  const double since = t_s - *entered_at_s_;  // the true time since the crossing is in [since, since + latency]
  // Distances from the boundary crossed, into the section.
  const double a = train.max_accel_mps2;
  // Nearest: braking hardest since the crossing (which increases with the time, so the
  // shortest time gives it), or for a train that may reverse, braking on into reverse
  // (concave in the time, so the smaller of its two ends).
  const auto reversing = [&](double t) { return v.lo * t - a * t * t / 2; };
  double near = train.reversible ? std::min(reversing(since), reversing(since + entered_latency_s_))
                                 : min_distance(v.lo, since);
  double far = max_distance(v.hi, since + entered_latency_s_);
  // Inside the occupied section, as last reported: the report may be up to the latency
  // old (and the port unseen longer still), so the train may have gone past the far end
  // (or, reversing, back over the near one) by what it covers in that time.
  const double past_end = train.max_speed_mps * (params_.crossing_latency_s + std::max(0.0, unseen_s));
  near = std::clamp(near, train.reversible ? -past_end : 0.0, sec.length_m);
  far = std::clamp(far, near, sec.length_m + past_end);
  if (direction_ > 0) {
    out.lo_s = sec.start_s + near;
    out.hi_s = sec.start_s + far;
  } else {
    out.lo_s = sec.end_s() - far;
    out.hi_s = sec.end_s() - near;
  }
  return out;
}

}  // namespace covtrack::lenz
