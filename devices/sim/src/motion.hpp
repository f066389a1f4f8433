#pragma once
// Ground-truth trajectories of the simulated tracker.
#include <cstdint>
#include <random>

#include "covtrack/devices/sim/sim_driver.hpp"

namespace covtrack::sim {

class Motion {
 public:
  Motion(const MotionConfig& config, std::uint64_t seed);
  // Pose of the rig at t seconds since start. Calls must come with t non-decreasing
  // (the random walk integrates between them).
  Pose rig_at(double t_s);

 private:
  Pose along_waypoints(double t_s) const;
  Pose random_walk_step(double t_s);

  MotionConfig config_;
  std::mt19937_64 rng_;
  Pose walk_ = Pose::Identity();
  double walk_t_s_ = 0;
};

// Sensor i rides the rig at i * spacing along the rig's y axis.
Pose sensor_on_rig(const Pose& rig, std::size_t index, double spacing_m);

}  // namespace covtrack::sim
