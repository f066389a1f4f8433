#pragma once
// Converters between the canonical covariance convention (BODY: right perturbation,
// translation first) and the two others a user meets: ROS (PARENT: position and
// rotation errors both in the parent frame) and GTSAM (rotation first, right
// perturbation). protocol/README.md states each one.
#include <cstdint>

#include "covtrack/protocol/se3.hpp"

namespace covtrack {

enum class CovarianceConvention : std::int8_t { Body = 0, Parent = 1, Gtsam = 2 };

// Exact for GTSAM (a permutation); first order for PARENT, whose errors relate to the
// body tangent through blockdiag(R, R).
Mat6 body_to_parent(const Pose& T_parent_child, const Mat6& cov_body);
Mat6 parent_to_body(const Pose& T_parent_child, const Mat6& cov_parent);
Mat6 body_to_gtsam(const Mat6& cov_body);
Mat6 gtsam_to_body(const Mat6& cov_gtsam);

Mat6 convert_covariance(const Pose& T_parent_child, const Mat6& cov,
                        CovarianceConvention from, CovarianceConvention to);

}  // namespace covtrack
