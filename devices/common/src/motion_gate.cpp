#include "covtrack/devices/motion_gate.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace covtrack {
namespace {

// The still filter's jerk noise (1 sigma per axis): a hand held still trembles with
// about this much. The level multiplies it, up to kMaxLevel.
constexpr double kStillJerk_mps3 = 3;
constexpr double kStillAngularJerk_radps3 = 30;
constexpr double kMaxLevel = 300;
// chi-square(6) quantiles of the innovation test: beyond 97.5 % the covariance is widened
// to cover the innovation (a clean record lands there 2.5 % of the time, and then only
// gains a little covariance along one direction); beyond 99.9 % the record is DEGRADED.
constexpr double kWidenChi2 = 14.449;
constexpr double kDegradeChi2 = 22.458;
// A widened covariance puts the prediction at this chi-square from the record: well
// inside the 99.9 % region, without making clean records much more conservative (the
// mean NEES of a clean stream drops by about 0.1).
constexpr double kCoverChi2 = 10;
// chi-square(3) median: what the recent innovations' median would be against the
// record's noise alone if the prediction were exact.
constexpr double kMedianChi2Dof3 = 2.366;
constexpr double kMaxStepUp = 3, kMaxStepDown = 1.5;
// Slack of the physics test in sigmas of the two records' noise.
constexpr double kPhysicsSigmas = 5;
// After this silence the prediction means nothing: start the stream again.
constexpr double kGap_s = 0.5;
// This many drops in a row: the filter, not the records, is wrong (it may have started
// on a corrupt record): start again from the newest.
constexpr int kRestartAfterRejections = 5;

double largest_sigma(const Mat3& covariance) {
  return std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Mat3>(covariance).eigenvalues().maxCoeff()));
}

Mat6 rotate_blocks(const Mat3& R) {
  Mat6 A = Mat6::Zero();
  A.topLeftCorner<3, 3>() = R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

}  // namespace

MotionGate::MotionGate(const MotionLimits& limits, double min_interval_s)
    : limits_(limits), min_interval_s_(min_interval_s) {}

GateVerdict MotionGate::check(const Pose& T, const Mat6& covariance, TrackingStatus status,
                              double time_s) {
  GateVerdict v{GateVerdict::Kind::Publish, status, covariance, {}};
  if (!limits_.enabled) return v;
  // The record's covariance is about its body axes; the filter works in the parent's.
  const Mat6 A = rotate_blocks(T.linear());
  const Mat6 C = A * covariance * A.transpose();
  if (state_ == State::Empty || time_s - last_time_s_ > kGap_s) {
    start_from(T, C, time_s);
    return {GateVerdict::Kind::Hold, status, covariance, {}};
  }

  const double dt = std::max(time_s - last_time_s_, min_interval_s_);
  last_time_s_ = time_s;
  predict(dt);
  if (std::string why = implausible(T, C, time_s); !why.empty()) {
    // A held record was never published: of two records that disagree, trust neither
    // and check the next one against the newer.
    if (state_ == State::Held || ++rejected_in_a_row_ >= kRestartAfterRejections) start_from(T, C, time_s);
    return {GateVerdict::Kind::Reject, status, covariance, why};
  }
  rejected_in_a_row_ = 0;
  state_ = State::Tracking;
  last_published_ = T;
  last_published_covariance_ = C;
  last_published_time_s_ = time_s;

  Vec6 nu;
  nu << T.translation() - position_, so3_log(T.linear() * rotation_.transpose());
  // The host times a record only to within about a report period (records are read in
  // bursts, the reading thread shares the machine): along the motion, that is distance.
  const Mat6 S = P_.topLeftCorner<6, 6>() + C + velocity_ * velocity_.transpose() * (min_interval_s_ * min_interval_s_);
  adapt(nu, C);
  const double d2 = nu.dot(S.ldlt().solve(nu));
  if (d2 <= kWidenChi2) {
    update(nu, C);
    return v;
  }
  // Possible but surprising: the record, or the prediction, is wrong. Either way the
  // truth lies within the record's noise and the prediction's spread, stretched along
  // the innovation until the prediction is an ordinary distance from the record:
  // nu' (S + k nu nu')^-1 nu = d2 / (1 + k d2) = kCoverChi2.
  const double k = (d2 - kCoverChi2) / (kCoverChi2 * d2);
  const Mat6 covering = S + k * nu * nu.transpose();
  update(nu, covering);
  v.covariance = A.transpose() * covering * A;
  if (d2 > kDegradeChi2) {
    v.status = status == TrackingStatus::Ok ? TrackingStatus::Degraded : status;
    v.reason = fmt::format("innovation chi-square {:.0f} (99.9 % limit {:.1f}): covariance widened", d2,
                           kDegradeChi2);
  }
  return v;
}

void MotionGate::start_from(const Pose& T, const Mat6& C, double time_s) {
  position_ = T.translation();
  rotation_ = T.linear();
  velocity_.setZero();
  acceleration_.setZero();
  // Unknown velocities and accelerations: anything up to the limits.
  P_.setZero();
  P_.topLeftCorner<6, 6>() = C;
  const auto third_squared = [](double limit) { return limit * limit / 9; };
  P_.block<3, 3>(6, 6) = Mat3::Identity() * third_squared(limits_.max_speed_mps);
  P_.block<3, 3>(9, 9) = Mat3::Identity() * third_squared(limits_.max_angular_rate_radps);
  P_.block<3, 3>(12, 12) = Mat3::Identity() * third_squared(limits_.max_accel_mps2);
  P_.block<3, 3>(15, 15) = Mat3::Identity() * third_squared(limits_.max_angular_accel_radps2);
  last_time_s_ = last_published_time_s_ = time_s;
  last_published_ = T;
  last_published_covariance_ = C;
  rejected_in_a_row_ = 0;
  linear_level_ = angular_level_ = 1;
  recent_count_ = 0;
  state_ = State::Held;
}

void MotionGate::predict(double dt) {
  const Vec6 step = velocity_ * dt + acceleration_ * dt * dt / 2;
  position_ += step.head<3>();
  rotation_ = so3_exp(step.tail<3>()) * rotation_;
  velocity_ += acceleration_ * dt;
  const Mat6 I = Mat6::Identity();
  Mat18 F = Mat18::Identity();
  F.block<6, 6>(0, 6) = I * dt;
  F.block<6, 6>(0, 12) = I * dt * dt / 2;
  F.block<6, 6>(6, 12) = I * dt;
  // Piecewise-constant jerk over the interval, independent per axis: its effect on
  // [pose, velocity, acceleration] is g = [dt^3/6, dt^2/2, dt].
  const Eigen::Vector3d g(dt * dt * dt / 6, dt * dt / 2, dt);
  Mat18 Q = Mat18::Zero();
  for (int i = 0; i < 6; ++i) {
    const double sigma = i < 3 ? kStillJerk_mps3 * linear_level_ : kStillAngularJerk_radps3 * angular_level_;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) Q(i + 6 * a, i + 6 * b) = sigma * sigma * g[a] * g[b];
  }
  P_ = F * P_ * F.transpose() + Q;
}

void MotionGate::update(const Vec6& nu, const Mat6& R) {
  const Mat6 S = P_.topLeftCorner<6, 6>() + R;
  const Eigen::Matrix<double, 18, 6> K = P_.leftCols<6>() * S.inverse();
  const Vec18 dx = K * nu;
  position_ += dx.segment<3>(0);
  rotation_ = so3_exp(dx.segment<3>(3)) * rotation_;
  velocity_ += dx.segment<6>(6);
  acceleration_ += dx.segment<6>(12);
  P_ -= K * P_.topRows<6>();
  P_ = (0.5 * (P_ + P_.transpose())).eval();
}

std::string MotionGate::implausible(const Pose& T, const Mat6& C, double time_s) const {
  const double dt = std::max(time_s - last_published_time_s_, min_interval_s_);
  const Mat6 both = C + last_published_covariance_;
  const double speed = (T.translation() - last_published_.translation()).norm() / dt;
  const double speed_limit =
      limits_.max_speed_mps + kPhysicsSigmas * largest_sigma(both.topLeftCorner<3, 3>()) / dt;
  if (speed > speed_limit)
    return fmt::format("implies {:.1f} m/s since the last record (max_speed_mps = {:g})", speed,
                       limits_.max_speed_mps);
  const double rate = so3_log(T.linear() * last_published_.linear().transpose()).norm() / dt;
  const double rate_limit = limits_.max_angular_rate_radps +
                            kPhysicsSigmas * largest_sigma(both.bottomRightCorner<3, 3>()) / dt;
  if (rate > rate_limit)
    return fmt::format("implies {:.1f} rad/s since the last record (max_angular_rate_radps = {:g})",
                       rate, limits_.max_angular_rate_radps);
  return {};
}

void MotionGate::adapt(const Vec6& nu, const Mat6& C) {
  // Innovations measured against the record's own noise only: their scatter beyond it
  // is what the prediction should spread.
  const std::size_t i = recent_count_++;
  recent_linear_[i] = nu.head<3>().dot(C.topLeftCorner<3, 3>().ldlt().solve(nu.head<3>()));
  recent_angular_[i] = nu.tail<3>().dot(C.bottomRightCorner<3, 3>().ldlt().solve(nu.tail<3>()));
  if (recent_count_ < kWindow) return;
  recent_count_ = 0;  // each decision on fresh innovations
  const auto adjust = [&](std::array<double, kWindow>& recent, double& level, int block) {
    std::nth_element(recent.begin(), recent.begin() + kWindow / 2, recent.end());
    const double wanted = recent[kWindow / 2] / kMedianChi2Dof3 - 1;
    const double spread = P_.block<3, 3>(block, block).trace() / C.block<3, 3>(block, block).trace();
    // Up only when the innovations clearly outgrow the prediction's spread (the median
    // of five is noisy; drifting up on noise would loosen the test for nothing).
    if (wanted > 2 * spread + 0.5) {
      const double step = std::min(std::sqrt(wanted / spread), kMaxStepUp);
      level = std::min(level * step, kMaxLevel);
      // The motion is here now: widen the filter's uncertainty of it at once rather
      // than through the next intervals' process noise.
      for (int order = 1; order < 3; ++order) P_.block<3, 3>(6 * order + block, 6 * order + block) *= step * step;
    } else if (wanted < spread) {
      level = std::max(level / kMaxStepDown, 1.0);
    }
  };
  adjust(recent_linear_, linear_level_, 0);
  adjust(recent_angular_, angular_level_, 3);
}

}  // namespace covtrack
