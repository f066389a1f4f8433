#pragma once
// The emulated train's motion along the track: a speed profile of (speed, hold time)
// steps, each reached at a constant acceleration, repeated forever. Exact and pure, so
// a test can ask where the train truly was at any time.
#include <string>
#include <vector>

#include "covtrack/protocol/result.hpp"

namespace covtrack::lenz {

struct SpeedStep {
  double speed_mps = 0;  // negative: backwards (only on a layout whose train is reversible)
  double hold_s = 0;  // time at that speed once reached
};

// "0.4:8,0.15:5,0:3,-0.1:2" -> steps; an error names the bad item.
Result<std::vector<SpeedStep>> parse_speed_profile(const std::string& text);

class TrainMotion {
 public:
  // Starts at rest at start_s; a profile that does not end at rest gets a final stop,
  // so that every repetition starts from rest too.
  TrainMotion(std::vector<SpeedStep> profile, double accel_mps2, double start_s = 0);

  double s_at(double t) const;      // along-track position (not wrapped), t >= 0 seconds
  double speed_at(double t) const;
  double cycle_s() const { return cycle_s_; }

 private:
  struct Phase {
    double t0, s0, v0, accel, duration;
  };
  const Phase& phase_at(double t_in_cycle) const;

  std::vector<Phase> phases_;
  double start_s_ = 0, cycle_s_ = 0, cycle_m_ = 0;
};

}  // namespace covtrack::lenz
