#include "covtrack/client/graph_osgar_matrix16.hpp"

#include <unsupported/Eigen/KroneckerProduct>

namespace covtrack::client {
namespace {

using Mat4 = Eigen::Matrix4d;
using Mat16x6 = Eigen::Matrix<double, 16, 6>;

constexpr int vec_index(int row, int col) { return col * 4 + row; }  // column-major

// vec(xi^) = H xi, xi^ = [skew(phi) rho; 0 0].
Mat16x6 hat_matrix() {
  Mat16x6 H = Mat16x6::Zero();
  for (int i = 0; i < 3; ++i) H(vec_index(i, 3), i) = 1.0;
  // skew(phi): (2,1) = phi_x, (1,2) = -phi_x, (0,2) = phi_y, (2,0) = -phi_y,
  //            (1,0) = phi_z, (0,1) = -phi_z
  H(vec_index(2, 1), 3) = 1.0;
  H(vec_index(1, 2), 3) = -1.0;
  H(vec_index(0, 2), 4) = 1.0;
  H(vec_index(2, 0), 4) = -1.0;
  H(vec_index(1, 0), 5) = 1.0;
  H(vec_index(0, 1), 5) = -1.0;
  return H;
}

Mat16 kron(const Mat4& A, const Mat4& B) { return Eigen::kroneckerProduct(A, B).eval(); }

}  // namespace

Mat16 matrix16_from_body(const Pose& T, const Mat6& body) {
  const Mat16x6 J = kron(Mat4::Identity(), T.matrix()) * hat_matrix();  // vec(M xi^)
  return J * body * J.transpose();
}

Mat6 body_from_matrix16(const Pose& T, const Mat16& covariance) {
  // H^T H = diag(1,1,1,2,2,2), so the pseudo-inverse (H^T H)^-1 H^T averages the two
  // skew entries of each rotation component: the least-squares projection.
  const Mat16x6 H = hat_matrix();
  Eigen::Matrix<double, 6, 16> G = (H.transpose() * H).inverse() * H.transpose();
  const Eigen::Matrix<double, 6, 16> J = G * kron(Mat4::Identity(), T.inverse().matrix());
  const Mat6 out = J * covariance * J.transpose();
  return 0.5 * (out + out.transpose());
}

MatrixEstimate osgar_propagate(const MatrixEstimate& parent, const Pose& T_parent_child,
                              const Mat6& body_covariance) {
  const Mat4 M = T_parent_child.matrix();
  // dN_j = dN_i M + N_i dM
  const Mat16 A = kron(M.transpose(), Mat4::Identity());
  const Mat16 B = kron(Mat4::Identity(), parent.N);
  MatrixEstimate out;
  out.N = parent.N * M;
  out.covariance = A * parent.covariance * A.transpose() +
                   B * matrix16_from_body(T_parent_child, body_covariance) * B.transpose();
  return out;
}

UncertainPose osgar_relative(const MatrixEstimate& root_A, const MatrixEstimate& root_B) {
  const Mat4 inv_A = root_A.N.inverse();
  const Mat4 T = inv_A * root_B.N;
  // d(inv(N_A) N_B) = -inv(N_A) dN_A inv(N_A) N_B + inv(N_A) dN_B
  const Mat16 KA = -kron(T.transpose(), inv_A);
  const Mat16 KB = kron(Mat4::Identity(), inv_A);
  const Mat16 cov = KA * root_A.covariance * KA.transpose() + KB * root_B.covariance * KB.transpose();
  UncertainPose out;
  out.T.matrix() = T;
  out.covariance = body_from_matrix16(out.T, cov);
  return out;
}

}  // namespace covtrack::client
