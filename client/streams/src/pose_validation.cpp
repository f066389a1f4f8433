#include "covtrack/client/pose_validation.hpp"

#include <cmath>

#include "covtrack/protocol/covariance_check.hpp"

namespace covtrack::client {
namespace {
constexpr double kQuaternionNormTolerance = 1e-6;

bool finite_position(const pose_cov_t& msg) {
  for (double v : msg.position_m)
    if (!std::isfinite(v)) return false;
  return true;
}
}  // namespace

std::optional<std::string> rejection_reason(const pose_cov_t& msg) {
  if (msg.status < pose_cov_t::STATUS_OK || msg.status > pose_cov_t::STATUS_LOST)
    return "unknown status " + std::to_string(msg.status);
  if (msg.status == pose_cov_t::STATUS_LOST) return std::nullopt;
  if (!finite_position(msg)) return "non-finite position";
  if (!(quaternion_norm_error(msg) <= kQuaternionNormTolerance))
    return "quaternion is not of unit norm";
  if (msg.covariance_convention < pose_cov_t::CONVENTION_BODY ||
      msg.covariance_convention > pose_cov_t::CONVENTION_GTSAM)
    return "unknown covariance convention " + std::to_string(msg.covariance_convention);
  const Mat6 cov = Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(msg.covariance);
  if (auto problem = check_covariance(cov))
    return std::string("covariance ") + to_string(problem->defect) + ": " + problem->detail;
  return std::nullopt;
}

TrackedTransform to_tracked_transform(const pose_cov_t& msg, std::int64_t receive_time_us) {
  TrackedTransform t;
  t.stream = {msg.device, msg.sensor};
  t.parent_frame = msg.parent_frame;
  t.child_frame = msg.child_frame;
  t.status = static_cast<TrackingStatus>(msg.status);
  // A LOST message's pose is not checked and may hold a zero quaternion or NaNs: keep
  // identity then rather than propagating NaNs into the transform graph.
  const bool usable_pose =
      !t.lost() || (finite_position(msg) && quaternion_norm_error(msg) <= kQuaternionNormTolerance);
  if (usable_pose) t.T_parent_child = pose_of(msg);
  // Infinite uncertainty, whatever the sender put in a LOST message's matrix.
  t.covariance = t.lost() ? lost_covariance() : body_covariance_of(msg);
  t.measurement_time_us = msg.measurement_time_us;
  t.publish_time_us = msg.publish_time_us;
  t.receive_time_us = receive_time_us;
  t.sequence = msg.sequence;
  return t;
}

}  // namespace covtrack::client
