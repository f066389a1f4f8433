#include "covtrack/protocol/se3.hpp"

#include <cmath>

namespace covtrack {
namespace {
// Below this angle the closed forms lose precision; their Taylor series take over.
constexpr double kSmallAngle = 1e-5;
}  // namespace

Mat3 skew(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Mat3 so3_exp(const Vec3& phi) {
  const double theta = phi.norm();
  if (theta < kSmallAngle) {
    const Mat3 K = skew(phi);
    return Mat3::Identity() + K + 0.5 * K * K;
  }
  return Eigen::AngleAxisd(theta, phi / theta).toRotationMatrix();
}

Vec3 so3_log(const Mat3& R) {
  Eigen::Quaterniond q(R);
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // the short way round
  const double n = q.vec().norm();
  if (n < kSmallAngle) {
    // 2 atan2(n, w) / n ~ (2 / w) (1 - n^2 / (3 w^2))
    return (2.0 / q.w()) * (1.0 - n * n / (3.0 * q.w() * q.w())) * q.vec();
  }
  return (2.0 * std::atan2(n, q.w()) / n) * q.vec();
}

Mat3 so3_left_jacobian(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 K = skew(phi);
  if (theta < kSmallAngle) return Mat3::Identity() + 0.5 * K + K * K / 6.0;
  const double t2 = theta * theta;
  return Mat3::Identity() + (1 - std::cos(theta)) / t2 * K +
         (theta - std::sin(theta)) / (t2 * theta) * K * K;
}

Mat3 so3_left_jacobian_inverse(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 K = skew(phi);
  if (theta < kSmallAngle) return Mat3::Identity() - 0.5 * K + K * K / 12.0;
  const double c = 1.0 / (theta * theta) -
                   (1 + std::cos(theta)) / (2 * theta * std::sin(theta));
  return Mat3::Identity() - 0.5 * K + c * K * K;
}

Pose se3_exp(const Vec6& xi) {
  const Vec3 rho = xi.head<3>();
  const Vec3 phi = xi.tail<3>();
  Pose T = Pose::Identity();
  T.linear() = so3_exp(phi);
  T.translation() = so3_left_jacobian(phi) * rho;
  return T;
}

Vec6 se3_log(const Pose& T) {
  const Vec3 phi = so3_log(T.linear());
  Vec6 xi;
  xi << so3_left_jacobian_inverse(phi) * T.translation(), phi;
  return xi;
}

Mat6 se3_adjoint(const Pose& T) {
  const Mat3 R = T.linear();
  Mat6 A = Mat6::Zero();
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = skew(T.translation()) * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

namespace {
// The coupling block Q(rho, phi) of the SE(3) left Jacobian (Barfoot, "State
// Estimation for Robotics", eq. 7.86), with its series for small angles.
Mat3 se3_q_block(const Vec3& rho, const Vec3& phi) {
  const Mat3 P = skew(phi);
  const Mat3 Rh = skew(rho);
  const double theta = phi.norm();
  double a, b, c;
  if (theta < 1e-3) {
    const double t2 = theta * theta;
    a = 1.0 / 6.0 - t2 / 120.0;
    b = 1.0 / 24.0 - t2 / 720.0;
    c = 1.0 / 120.0;
  } else {
    const double t2 = theta * theta, t3 = t2 * theta, t4 = t3 * theta, t5 = t4 * theta;
    a = (theta - std::sin(theta)) / t3;
    b = (t2 + 2 * std::cos(theta) - 2) / (2 * t4);
    c = (2 * theta - 3 * std::sin(theta) + theta * std::cos(theta)) / (2 * t5);
  }
  return 0.5 * Rh + a * (P * Rh + Rh * P + P * Rh * P) +
         b * (P * P * Rh + Rh * P * P - 3 * P * Rh * P) +
         c * (P * Rh * P * P + P * P * Rh * P);
}
}  // namespace

Mat6 se3_left_jacobian(const Vec6& xi) {
  const Vec3 rho = xi.head<3>();
  const Vec3 phi = xi.tail<3>();
  const Mat3 J = so3_left_jacobian(phi);
  Mat6 out = Mat6::Zero();
  out.topLeftCorner<3, 3>() = J;
  out.topRightCorner<3, 3>() = se3_q_block(rho, phi);
  out.bottomRightCorner<3, 3>() = J;
  return out;
}

Mat6 se3_right_jacobian(const Vec6& xi) { return se3_left_jacobian(-xi); }

Pose boxplus(const Pose& T, const Vec6& xi) { return T * se3_exp(xi); }

Vec6 boxminus(const Pose& a, const Pose& b) { return se3_log(b.inverse() * a); }

Pose pose_from(const Vec3& position_m, const Eigen::Quaterniond& q) {
  Pose T = Pose::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = position_m;
  return T;
}

}  // namespace covtrack
