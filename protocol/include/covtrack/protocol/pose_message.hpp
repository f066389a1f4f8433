#pragma once
// Conversions between the wire message and Eigen types.
#include <covtrack/pose_cov_t.hpp>
#include <covtrack/truth_pose_t.hpp>

#include "covtrack/protocol/covariance_conventions.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack {

enum class TrackingStatus : std::int8_t { Ok = 0, Degraded = 1, Lost = 2 };
const char* to_string(TrackingStatus status);

// The covariance a LOST report carries: +infinity on the diagonal, 0 elsewhere
// (protocol/README.md). Built entry by entry because Identity() * infinity puts
// 0 * inf = NaN off the diagonal.
Mat6 lost_covariance();

Pose pose_of(const pose_cov_t& msg);
Pose pose_of(const truth_pose_t& msg);
// The message's covariance, converted to the canonical BODY convention.
Mat6 body_covariance_of(const pose_cov_t& msg);

// Writes pose and covariance (given in BODY) into the message, in the BODY convention.
void set_pose(pose_cov_t& msg, const Pose& T_parent_child, const Mat6& cov_body);
void set_pose(truth_pose_t& msg, const Pose& T_parent_child);

// How far the wire quaternion is from unit norm (a sender bug if above ~1e-6).
double quaternion_norm_error(const pose_cov_t& msg);

}  // namespace covtrack
