#include "covtrack/devices/lenz/dead_reckoning.hpp"

#include <algorithm>
#include <cmath>

namespace covtrack::lenz {

DeadReckoner::DeadReckoner(const TrackLayout& layout, DeadReckoningParams params)
    : layout_(layout), params_(params) {}

void DeadReckoner::reset() {
  section_.reset();
  entered_at_s_.reset();
  entry_speed_.reset();
}

void DeadReckoner::lose() { reset(); }

void DeadReckoner::on_occupancy(const std::optional<std::vector<bool>>& occupied, double t_s) {
  if (!occupied) return lose();
  const auto& occ = *occupied;
  const auto count = std::count(occ.begin(), occ.end(), true);
  if (count == 0) return lose();
  if (section_) {
    const std::size_t here = *section_, next = layout_.next(here);
    if (occ[next]) return enter(next, t_s);  // crossed the boundary (here may still read occupied)
    // Still here, possibly with the rear pickups still on the section just left.
    const std::size_t prev = layout_.previous(here);
    if (occ[here] && count == 1 + (occ[prev] && prev != here ? 1 : 0)) return;
  }
  // First report, or a pattern the train cannot produce from where we thought it was
  // (a skipped section, a jump, a move backwards): start again from what is occupied.
  if (section_) ++inconsistencies_;
  reset();
  if (count == 1) section_ = static_cast<std::size_t>(std::find(occ.begin(), occ.end(), true) - occ.begin());
  // Two or more occupied: several candidate sections, no estimate until it clears up.
}

void DeadReckoner::enter(std::size_t section, double t_s) {
  // Speed at the boundary from the traversal of the section just left, if its entry was seen.
  if (entered_at_s_) entry_speed_ = speed_after(*section_, t_s - *entered_at_s_);
  else entry_speed_.reset();
  section_ = section;
  entered_at_s_ = t_s;
}

DeadReckoner::SpeedRange DeadReckoner::speed_after(std::size_t section, double traversal_s) const {
  const double a = layout_.train().max_accel_mps2, v_max = layout_.train().max_speed_mps;
  const double length = layout_.sections()[section].length_m;
  const double L = params_.crossing_latency_s;
  // Each crossing was detected up to L late, so the true traversal time is T +- L.
  const double t_short = std::max(traversal_s - L, 1e-3), t_long = traversal_s + L;
  // Highest end speed: accelerating all the way (or from a standstill, if the average
  // is too low for that). Lowest: decelerating all the way, or stopped.
  const auto highest = [&](double T) {
    const double mean = length / T;
    return mean >= a * T / 2 ? mean + a * T / 2 : std::sqrt(2 * a * length);
  };
  const double hi = std::min(v_max, highest(t_short));
  const double lo = std::max(0.0, length / t_long - a * t_long / 2);
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

AlongTrack DeadReckoner::estimate(double t_s) const {
  AlongTrack out;
  if (!section_) return out;
  const Section& sec = layout_.sections()[*section_];
  out.section = *section_;
  out.lo_s = sec.start_s;
  out.hi_s = sec.end_s();
  if (!entered_at_s_) {
    out.state = AlongTrack::State::WholeSection;
    return out;
  }
  out.state = AlongTrack::State::DeadReckoning;
  const SpeedRange v = entry_speed_.value_or(SpeedRange{0, layout_.train().max_speed_mps});
  const double since = t_s - *entered_at_s_;  // the true time since the crossing is in [since, since + L]
  const double near = min_distance(v.lo, since);
  const double far = max_distance(v.hi, since + params_.crossing_latency_s);
  // Inside the occupied section, as last reported: the report may be up to the latency
  // old, so the train may have gone past the end by what it covers in that time.
  const double past_end = layout_.train().max_speed_mps * params_.crossing_latency_s;
  out.lo_s = sec.start_s + std::min(near, sec.length_m);
  out.hi_s = sec.start_s + std::min(far, sec.length_m + past_end);
  return out;
}

}  // namespace covtrack::lenz
