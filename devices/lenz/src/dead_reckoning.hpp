#pragma once
// Where the locomotive can be, from section occupancy alone (the dissertation's model-train
// tracker, section 7.3 in docs/background.md, done honestly).
//
// The dissertation estimates the speed from the time spent in the previous section, puts
// the train at s0 + v t, and grows the uncertainty with (v_max - v) t. That misses a train
// that slows down or stops, and lets the uncertainty run past the section that is
// known to be occupied. Here the estimate is the set of positions the train can reach:
// - the locomotive crossed into the section at a detection time, give or take the
//   detection latency (the configured one, plus however long the reader was held up
//   before it looked, when the daemon itself was stalled);
// - its speed then lies in a range derived from the previous section's length and
//   traversal time and the train's largest acceleration (a train that averaged v over
//   T seconds ends between v - aT/2 and v + aT/2, never below 0 nor above v_max);
// - from there it may slow down to a stop or speed up to v_max, at most at that
//   acceleration, and never runs backwards unless the layout says it may (then it may
//   also come back towards the boundary it crossed, in either direction);
// - and it is inside the occupied section.
// The interval [lo, hi] therefore contains the truth whenever the train obeys its
// limits; it is reported as a Gaussian whose 99% interval is exactly [lo, hi].
// Pure: times are passed in, in seconds on any monotonic clock.
#include <cstddef>
#include <optional>
#include <vector>

#include "covtrack/devices/lenz/lenz_driver.hpp"
#include "track_layout.hpp"

namespace covtrack::lenz {

struct AlongTrack {
  enum class State { Lost, WholeSection, DeadReckoning } state = State::Lost;
  std::size_t section = 0;
  double lo_s = 0, hi_s = 0;  // interval on the loop, lo_s <= hi_s (hi_s may pass length)
  double mid_s() const { return (lo_s + hi_s) / 2; }
};

// z for a two-sided 99% interval of a Gaussian.
inline constexpr double kZ99 = 2.5758293035489;

class DeadReckoner {
 public:
  DeadReckoner(const TrackLayout& layout, DeadReckoningParams params);

  // The occupied state of every section (index as in the layout), after any change;
  // nothing when some section's input is not known yet. `read_late_s`: how much longer
  // than the configured latency the report may have waited to be read (a reader that
  // was held up; 0 when it was looking).
  void on_occupancy(const std::optional<std::vector<bool>>& occupied, double t_s, double read_late_s = 0);
  // Whether the train can have produced this occupancy from where it is thought to be
  // (crossed ahead, stayed, or backed up if it may); true while there is no estimate.
  // A pattern it cannot produce is either missed crossings or a corrupt report.
  bool is_possible_move(const std::vector<bool>& occupied) const;
  // `unseen_s`: how long the reader has not seen the port, when it was held up (0 when it
  // was looking): a crossing out of the section may have come unread that long too.
  AlongTrack estimate(double t_s, double unseen_s = 0) const;
  // Forget everything (after a reconnect: crossings may have been missed).
  void reset();
  // Counts of occupancy patterns the train cannot produce (for diagnostics).
  std::size_t inconsistencies() const { return inconsistencies_; }

 private:
  struct SpeedRange { double lo = 0, hi = 0; };
  enum class Move { Ahead, Stay, Behind, Impossible };
  Move classify(const std::vector<bool>& occupied) const;  // requires section_
  SpeedRange speed_after(std::size_t section, double traversal_s, double latency_before_s, double latency_after_s,
                         bool same_direction) const;
  void enter(std::size_t section, int direction, double t_s, double latency_s);
  void lose();
  double min_distance(double v, double t) const;
  double max_distance(double v, double t) const;

  const TrackLayout& layout_;
  DeadReckoningParams params_;
  std::optional<std::size_t> section_;
  std::optional<double> entered_at_s_;   // detection time of the crossing into section_
  double entered_latency_s_ = 0;         // how late that detection may have been
  std::optional<SpeedRange> entry_speed_;
  int direction_ = +1;  // +1: in loop order; -1: backwards (reversible layouts only)
  std::size_t inconsistencies_ = 0;
};

}  // namespace covtrack::lenz
