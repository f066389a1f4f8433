#pragma once
// SE(3) and SO(3) maths shared by drivers and the client: the covariance convention
// (protocol/README.md) only has a meaning through these functions.
//
// Tangent order everywhere: xi = [rho (translation part), phi (rotation part)].
// Perturbations are on the right: T_true = T_est * Exp(xi).
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace covtrack {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Pose = Eigen::Isometry3d;

Mat3 skew(const Vec3& v);

Mat3 so3_exp(const Vec3& phi);
Vec3 so3_log(const Mat3& R);
// Left Jacobian J_l(phi): Exp(phi + d) ~ Exp(J_l(phi) d) Exp(phi).
Mat3 so3_left_jacobian(const Vec3& phi);
Mat3 so3_left_jacobian_inverse(const Vec3& phi);

Pose se3_exp(const Vec6& xi);
Vec6 se3_log(const Pose& T);
// Adjoint: T * Exp(xi) * T^-1 = Exp(Ad(T) xi).
Mat6 se3_adjoint(const Pose& T);
// Left Jacobian: Exp(xi + d) ~ Exp(J_l(xi) d) Exp(xi). The right Jacobian is J_l(-xi).
Mat6 se3_left_jacobian(const Vec6& xi);
Mat6 se3_right_jacobian(const Vec6& xi);

// T (+) xi = T * Exp(xi);  a (-) b = Log(b^-1 * a), so b (+) (a (-) b) = a.
Pose boxplus(const Pose& T, const Vec6& xi);
Vec6 boxminus(const Pose& a, const Pose& b);

// Rotation from a quaternion given as w, x, y, z (normalised here).
Pose pose_from(const Vec3& position_m, const Eigen::Quaterniond& q);

}  // namespace covtrack
