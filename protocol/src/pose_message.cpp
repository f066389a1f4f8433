#include "covtrack/protocol/pose_message.hpp"

#include <cmath>
#include <limits>

namespace covtrack {

const char* to_string(TrackingStatus status) {
  switch (status) {
    case TrackingStatus::Ok: return "OK";
    case TrackingStatus::Degraded: return "DEGRADED";
    case TrackingStatus::Lost: return "LOST";
  }
  return "?";
}

Mat6 lost_covariance() {
  Mat6 cov = Mat6::Zero();
  cov.diagonal().setConstant(std::numeric_limits<double>::infinity());
  return cov;
}

namespace {
template <typename Msg>
Pose pose_of_fields(const Msg& m) {
  const Eigen::Quaterniond q(m.orientation_wxyz[0], m.orientation_wxyz[1],
                             m.orientation_wxyz[2], m.orientation_wxyz[3]);
  return pose_from(Vec3(m.position_m[0], m.position_m[1], m.position_m[2]), q);
}

template <typename Msg>
void set_pose_fields(Msg& m, const Pose& T) {
  Eigen::Quaterniond q(T.linear());
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // one canonical sign on the wire
  for (int i = 0; i < 3; ++i) m.position_m[i] = T.translation()(i);
  m.orientation_wxyz[0] = q.w();
  m.orientation_wxyz[1] = q.x();
  m.orientation_wxyz[2] = q.y();
  m.orientation_wxyz[3] = q.z();
}
}  // namespace

Pose pose_of(const pose_cov_t& msg) { return pose_of_fields(msg); }
Pose pose_of(const truth_pose_t& msg) { return pose_of_fields(msg); }

Mat6 body_covariance_of(const pose_cov_t& msg) {
  const Mat6 cov = Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(msg.covariance);
  return convert_covariance(pose_of(msg), cov,
                            static_cast<CovarianceConvention>(msg.covariance_convention),
                            CovarianceConvention::Body);
}

void set_pose(pose_cov_t& msg, const Pose& T, const Mat6& cov_body) {
  set_pose_fields(msg, T);
  Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(msg.covariance) = cov_body;
  msg.covariance_convention = pose_cov_t::CONVENTION_BODY;
}

void set_pose(truth_pose_t& msg, const Pose& T) { set_pose_fields(msg, T); }

double quaternion_norm_error(const pose_cov_t& msg) {
  double n2 = 0;
  for (double v : msg.orientation_wxyz) n2 += v * v;
  return std::abs(std::sqrt(n2) - 1.0);
}

}  // namespace covtrack
