#pragma once
// Plausibility gate for one sensor's stream of measured poses. A record that framed
// correctly can still be corrupt: a flipped bit in a float moves a receiver by
// millimetres or metres, and a binary record without a checksum (Fastrak) has no other
// defence. Each pose is tested two ways:
//
// - physics: the speed and turn rate it implies since the last published record must be
//   within the configured limits (plus the records' noise); beyond them it is dropped;
// - statistics: a constant-acceleration Kalman filter predicts the pose; the
//   innovation's chi-square (6 dof) against the prediction's covariance plus the
//   record's own is tested at 99.9 %. A record that fails it is published DEGRADED with
//   its covariance widened by the innovation and the prediction's spread, so that it
//   covers the truth whether the record or the prediction is wrong.
//
// Human motion is smooth at tracker rates: over 8 ms a constant-acceleration prediction
// of a hand is good to a small fraction of a millimetre, so a corruption of a few
// sigmas shows even while the sensor moves. The filter's jerk noise adapts: the median
// of the last few innovations, which single corrupt records cannot move, raises it when
// real motion outruns the prediction (a tap, a sudden push). A stream starts, and starts
// again after a gap or a run of drops, with a held record: nothing is published until
// two consecutive records agree.
#include <array>
#include <cstddef>
#include <string>

#include <Eigen/Dense>

#include "covtrack/protocol/pose_message.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack {

struct MotionLimits {
  bool enabled = true;
  double max_speed_mps = 10;
  double max_accel_mps2 = 100;
  double max_angular_rate_radps = 30;
  double max_angular_accel_radps2 = 1000;
};

struct GateVerdict {
  enum class Kind {
    Publish,  // publish with `status` and `covariance`
    Hold,     // the first record of a stream: kept to check the next one against
    Reject,   // not physically possible: `reason` says why
  };
  Kind kind = Kind::Publish;
  TrackingStatus status = TrackingStatus::Ok;
  Mat6 covariance = Mat6::Zero();  // BODY convention, as the record's
  std::string reason;
};

class MotionGate {
 public:
  // `min_interval_s`: records cannot come faster than this (the unit's report period);
  // records read in one burst share a receive time, so the gate assumes this spacing.
  MotionGate(const MotionLimits& limits, double min_interval_s);

  GateVerdict check(const Pose& T_parent_child, const Mat6& covariance, TrackingStatus status,
                    double time_s);
  // Forget the stream (the sensor was LOST, the unit restarted).
  void restart() { state_ = State::Empty; }

 private:
  using Vec18 = Eigen::Matrix<double, 18, 1>;
  using Mat18 = Eigen::Matrix<double, 18, 18>;
  enum class State { Empty, Held, Tracking };

  void start_from(const Pose& T, const Mat6& spatial_covariance, double time_s);
  void predict(double dt);
  void update(const Vec6& innovation, const Mat6& measurement_covariance);
  std::string implausible(const Pose& T, const Mat6& C, double time_s) const;
  void adapt(const Vec6& innovation, const Mat6& measurement_covariance);

  MotionLimits limits_;
  double min_interval_s_;
  State state_ = State::Empty;
  double last_time_s_ = 0;
  int rejected_in_a_row_ = 0;
  // The last published record (parent frame) and its covariance: the physics test.
  Pose last_published_ = Pose::Identity();
  Mat6 last_published_covariance_ = Mat6::Zero();
  double last_published_time_s_ = 0;
  // Filter: nominal pose, velocities and accelerations (parent frame), and the error
  // state's covariance [position, rotation, velocity, angular velocity, acceleration,
  // angular acceleration].
  Vec3 position_ = Vec3::Zero();
  Mat3 rotation_ = Mat3::Identity();
  Vec6 velocity_ = Vec6::Zero();
  Vec6 acceleration_ = Vec6::Zero();
  Mat18 P_ = Mat18::Zero();
  // Jerk noise levels (multiples of the still level) and recent innovations.
  double linear_level_ = 1, angular_level_ = 1;
  static constexpr std::size_t kWindow = 5;
  std::array<double, kWindow> recent_linear_{}, recent_angular_{};
  std::size_t recent_count_ = 0;
};

}  // namespace covtrack
