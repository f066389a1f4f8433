#pragma once
// A tag's pose from its four corners, with a first-order covariance (BODY convention,
// protocol/README.md: T_true = T_est * Exp(xi), xi = [translation, rotation]).
//
// A square seen in perspective has two poses that fit (the tilt ambiguity); both come
// from OpenCV's IPPE_SQUARE and are polished by Levenberg-Marquardt. The covariance is
// (J^T Sigma_c^-1 J)^-1, J the Jacobian of the four projected corners w.r.t. xi, and the
// full 8x8 corner covariance
//   Sigma_c = diag(sigma^2 + extra_k^2) + M (edge_sigma^2 I + scale_sigma^2 1 1^T) M^T
//             + tilt_sigma^2 N N^T,
// M's column e the corners' displacement when edge e's line moves out by 1 px, N's when
// it turns so that its start moves out by 1 px and its end in by 1 px (extra_k:
// corner k's edge-shift term; see corner_noise.hpp). Corners are first corrected: each
// edge's line is moved back in by its predicted outward shift. The second pose is told apart from the best
// by the Mahalanobis distance, under Sigma_c, between the corners each predicts; below
// `ambiguity_chi2` the covariance gets the outer product of the step to it, so that it
// covers both. Near face-on, LM can pull both solutions into one minimum; the second is
// then IPPE's other one, unpolished.
#include <array>
#include <optional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "covtrack/protocol/camera_opencv.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::fiducial {

using CornerJacobian = Eigen::Matrix<double, 8, 6>;

struct PoseSolution {
  Pose T_camera_tag = Pose::Identity();
  double sse_px2 = 0;  // sum of squared corner reprojection errors
};

struct TagPose {
  PoseSolution best;
  std::optional<PoseSolution> second;
  Mat6 covariance = Mat6::Zero();  // BODY convention, inflation included
  double corner_sigma_px = 0;
  double ambiguity_chi2 = 0;       // the two poses' corners' Mahalanobis^2; inf without second
  bool ambiguous = false;          // the covariance was inflated to cover the second pose
  // What the pose was fitted to: the corners corrected for the predicted edge shifts and
  // the lens, undistorted (pinhole pixels), and their full covariance (a bundle's pose
  // stacks these of its tags).
  std::array<cv::Point2d, 4> corners_px{};
  Eigen::Matrix<double, 8, 8> corner_covariance = Eigen::Matrix<double, 8, 8>::Zero();
  // The corners' move for a one-sigma error of the tag's apparent scale (apparent_scale_mode):
  // its outer product is the part of corner_covariance that the frame's image formation
  // gives every tag of the frame alike (a bundle's tags share it: bundle_pose.hpp).
  Eigen::Matrix<double, 8, 1> apparent_scale_px = Eigen::Matrix<double, 8, 1>::Zero();
};

// The tag's corners in its own frame, in the detector's order (AprilTag 3's).
std::array<Vec3, 4> tag_corner_points(double size_m);

// d(pixel)/d(xi) of the point X (in the frame of T_camera_frame) under the pinhole
// projection, for the BODY perturbation T_camera_frame * Exp(xi).
Eigen::Matrix<double, 2, 6> point_jacobian(const Camera& camera, const Pose& T_camera_frame, const Vec3& X);

// d(corner pixels)/d(xi) at T_camera_tag, rows u0 v0 u1 v1 ..., pinhole projection.
CornerJacobian corner_jacobian(const Camera& camera, const Pose& T_camera_tag, double size_m);

// Per edge (corner k to k + 1): its outward shift (px) at its start and at its end.
using EdgeShifts = std::array<std::array<double, 2>, 4>;

// What the noise model says about one tag's corners.
struct CornerNoise {
  double sigma_px = 0.1;       // independent, per coordinate
  // Per edge end, the error of AprilTag's least-squares line through the edge's samples:
  // the ends of such a line are correlated -1/2, so a quarter of this variance moves the
  // edge's line out (both ends alike) and three quarters turn it (its ends opposite).
  double line_sigma_px = 0;
  double scale_sigma_px = 0;   // the four edges' common outward error
  double edge_sigma_px = 0;    // each edge's own outward error
  double tilt_sigma_px = 0;    // each edge's own turn: its ends' opposite outward errors
  std::array<double, 4> extra_px{};   // per corner, extra independent error (edge shift)
  // Per edge, a phase-locked edge's own outward error and turn (corner_noise.hpp).
  std::array<double, 4> locked_edge_px{}, locked_tilt_px{};
  EdgeShifts edge_shift_px{};  // predicted outward shifts of the edges' ends, removed
};

// Unit outward normals of the quad's edges (edge k runs from corner k to corner k + 1).
std::array<cv::Point2d, 4> edge_outward_normals(const std::array<cv::Point2d, 4>& corners_px);

// The corners of the quad whose edges are those of `corners_px` moved in along their
// outward normals by `shift_px` at each end (edge k runs from corner k to corner k + 1).
std::array<cv::Point2d, 4> move_edges_in(const std::array<cv::Point2d, 4>& corners_px,
                                         const EdgeShifts& shift_px);

// How the four corners (rows u0 v0 u1 v1 ...) move when one edge's line moves and the
// other three stay: column e (0-3) when edge e moves out along its normal by 1 px, column
// 4 + e when it turns, its start 1 px out and its end 1 px in.
Eigen::Matrix<double, 8, 8> edge_line_modes(const std::array<cv::Point2d, 4>& corners_px);

// How the corners move when all four edges move out by noise.scale_sigma_px: the scale
// term of corner_covariance is this vector's outer product.
Eigen::Matrix<double, 8, 1> apparent_scale_mode(const std::array<cv::Point2d, 4>& corners_px,
                                                const CornerNoise& noise);

// The full corner covariance of `noise` for a quad with these (corrected) corners.
Eigen::Matrix<double, 8, 8> corner_covariance(const std::array<cv::Point2d, 4>& corners_px,
                                              const CornerNoise& noise);

// sigma^2 (J^T J)^-1: the pose covariance from independent corner noise of sigma px.
Mat6 pose_covariance(const CornerJacobian& J, double corner_sigma_px);
// (J^T Sigma_c^-1 J)^-1 for a full 8x8 corner covariance.
Mat6 pose_covariance(const CornerJacobian& J, const Eigen::Matrix<double, 8, 8>& corner_covariance);

// Corner pixels are undistorted with the camera's distortion first; the noise model is
// applied to the undistorted corners. Fails on degenerate input (non-finite corners,
// a collapsed quad) or when no pose is found.
Result<TagPose> estimate_tag_pose(const Camera& camera,
                                  const std::array<cv::Point2d, 4>& corners_px, double size_m,
                                  const CornerNoise& noise, double ambiguity_chi2 = 40.0);

}  // namespace covtrack::fiducial
