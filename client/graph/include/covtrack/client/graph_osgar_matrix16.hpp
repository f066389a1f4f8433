#pragma once
// The osgAR dissertation's model (appendix B and section 4.9.1; docs/background.md), kept
// to compare against, never to use: each 4x4 transform carries a 16x16 covariance of its
// matrix entries, errors are additive (M_true = M + dM), and the cumulative transform of
// every frame is propagated down from the ROOT with eq. 29:
//   N_j = N_i M_ij,   dN_j = N_i dM_ij + dN_i M_ij   (first order, independent errors).
// The camera-to-object transform is then inv(N_camera) * N_object with the two cumulative
// errors taken as independent (eq. 6), so edges shared by both root paths count twice:
// the "exaggerated estimates" flaw the dissertation describes.
//
// Matrices are vectorised column-major (vec(A X B) = (B^T kron A) vec(X)).
#include <span>

#include "covtrack/client/graph_chain.hpp"

namespace covtrack::client {

using Mat16 = Eigen::Matrix<double, 16, 16>;

struct MatrixEstimate {
  Eigen::Matrix4d N = Eigen::Matrix4d::Identity();  // cumulative transform from the root
  Mat16 covariance = Mat16::Zero();                  // of vec(N)
};

// The 16-element covariance of a 4x4 transform whose BODY covariance is `body`:
// M Exp(xi) ~ M + M xi^, so dM = M xi^.
Mat16 matrix16_from_body(const Pose& T, const Mat6& body);
// Back to a 6x6 BODY covariance, for comparison: xi^ ~ T^-1 dM, then rho is the last
// column of T^-1 dM and phi its skew-symmetric part (the least-squares projection onto
// se(3); the symmetric part, a non-rigid error the 16-element model allows, is dropped).
Mat6 body_from_matrix16(const Pose& T, const Mat16& covariance);

// One step of eq. 29: the root-to-child estimate from the root-to-parent one.
MatrixEstimate osgar_propagate(const MatrixEstimate& parent, const Pose& T_parent_child,
                              const Mat6& body_covariance);
// T_A_B = inv(N_A) N_B with the two root-path errors taken as independent (eq. 6).
UncertainPose osgar_relative(const MatrixEstimate& root_A, const MatrixEstimate& root_B);

}  // namespace covtrack::client
