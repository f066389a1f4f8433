#include "covtrack/protocol/covariance_conventions.hpp"

#include <stdexcept>

namespace covtrack {
namespace {
// To first order T * Exp([rho, phi]) moves the position by R rho and the rotation by
// Exp(R phi) on the left: both parent-frame errors are the body ones rotated by R.
Mat6 body_to_parent_jacobian(const Pose& T) {
  Mat6 J = Mat6::Zero();
  J.topLeftCorner<3, 3>() = T.linear();
  J.bottomRightCorner<3, 3>() = T.linear();
  return J;
}

Mat6 swap_halves(const Mat6& c) {
  Mat6 out;
  out << c.bottomRightCorner<3, 3>(), c.bottomLeftCorner<3, 3>(),
      c.topRightCorner<3, 3>(), c.topLeftCorner<3, 3>();
  return out;
}
}  // namespace

Mat6 body_to_parent(const Pose& T, const Mat6& cov_body) {
  const Mat6 J = body_to_parent_jacobian(T);
  return J * cov_body * J.transpose();
}

Mat6 parent_to_body(const Pose& T, const Mat6& cov_parent) {
  const Mat6 J = body_to_parent_jacobian(T).transpose();  // blockdiag(R^T, R^T)
  return J * cov_parent * J.transpose();
}

Mat6 body_to_gtsam(const Mat6& cov_body) { return swap_halves(cov_body); }
Mat6 gtsam_to_body(const Mat6& cov_gtsam) { return swap_halves(cov_gtsam); }

Mat6 convert_covariance(const Pose& T, const Mat6& cov, CovarianceConvention from,
                        CovarianceConvention to) {
  Mat6 body;
  switch (from) {
    case CovarianceConvention::Body: body = cov; break;
    case CovarianceConvention::Parent: body = parent_to_body(T, cov); break;
    case CovarianceConvention::Gtsam: body = gtsam_to_body(cov); break;
    default: throw std::invalid_argument("unknown covariance convention");
  }
  switch (to) {
    case CovarianceConvention::Body: return body;
    case CovarianceConvention::Parent: return body_to_parent(T, body);
    case CovarianceConvention::Gtsam: return body_to_gtsam(body);
  }
  throw std::invalid_argument("unknown covariance convention");
}

}  // namespace covtrack
