#pragma once
// Calibrating the corner noise model to one camera from a rigid board of tags with a known
// layout, moved in front of it (no true poses needed): `covtrack calibrate-fiducial`.
//
// Each tag of the board, seen with at least two others, is predicted from the others: the
// board's pose from their corners alone (bundle_pose.hpp) places the tag's four corners,
// with the covariance Q = J P J^T of that prediction (P the others' pose covariance). The
// tag's own corners (corrected for the white-cell shift and the lens, not for the
// apparent-scale bias) minus that prediction is its residual r, whose distribution under
// the model is
//   r ~ N(polarity * b * blur * M 1,
//         kI^2 D + W + kE^2 e^2 M M^T + kS^2 s^2 M 1 1^T M^T + t^2 N N^T + Q)
// (M, N: the corners' motion when an edge's line moves out or turns; D, W, e, s, t: the
// starting model's independent variances (noise and floor; what the white-cell shift
// correction misses) and edge, scale and turn spreads at this detection's blur, size and
// contrast). The fit finds, by maximum likelihood over all residuals, this camera's bias
// b (corner_scale_bias_per_blur) and one factor per term (kI on gain, floor and aligned;
// kS, kE on the scale and edge terms' floor and growth per blur; the turn term t and the
// white-cell shift's residual W are kept: a board cannot separate them from kI): the
// camera's level of each error, the shape in blur, size and contrast kept from the
// population calibration (one camera seldom spans enough blur to fit the shape).
// A residual whose NEES under the fit is above 100 (a gross error: a wrong quad, a tag
// peeled off the board) is left out and the fit repeated once. devices/fiducial/README.md,
// "Per-camera calibration".
#include <vector>

#include "bundle_pose.hpp"
#include "corner_noise.hpp"
#include "covtrack/protocol/camera_opencv.hpp"
#include "covtrack/protocol/result.hpp"
#include "tag_detector.hpp"

namespace covtrack::fiducial {

// One of the board's tags found in one frame, with what the corner model reads there.
struct BoardDetection {
  Detection detection;
  CornerInputs inputs;
};

// The board's tags found in one frame (each id once).
using BoardFrame = std::vector<BoardDetection>;

// How well the tags of the board agree with each other: per tag in view, the chi-square
// (6 dof) between its own pose and where the other tags put it (BundlePose::agreement),
// the NEES of the known relative poses.
struct BoardConsistency {
  int tags = 0;
  double mean_chi2 = 0;     // 6 when the covariances are honest (a single small tag's pose
                            // is not linear enough for that: a few far-off flips weigh in)
  double median_chi2 = 0;   // 5.35 when honest
  double above_99 = 0;      // fraction above chi-square(6)'s 99% quantile (0.01 honest)
};

struct BoardFit {
  CornerNoiseModel model;    // the starting model with this camera's values
  double scale_bias_per_blur = 0;
  double independent_factor = 1, scale_factor = 1, edge_factor = 1;
  // Their standard errors, from the likelihood's curvature: what these frames can tell.
  double scale_bias_se = 0, independent_se = 0, scale_se = 0, edge_se = 0;
  int frames_used = 0;       // frames with at least three of the board's tags
  int residuals = 0;         // tag views the fit used
  int left_out = 0;          // residuals left out as outliers
  int passes = 0;            // residuals built anew under each fit until it settled
  bool settled = false;      // the last pass moved no value by a tenth of its standard error
  double mean_residual_nees = 0;  // of the used residuals under the fit (8 expected)
  double median_blur_px = 0;
  BoardConsistency before, after;  // under the starting model and under the fitted one
};

// The board's tags in a grey frame: detected, each id of `board` once (a repeated id is
// left out: which copy is on the board cannot be told), with the corner model's inputs.
BoardFrame find_board(const cv::Mat& gray, TagDetector& detector, const TagBundle& board);

// Fits this camera's model from `frames` of `board`, starting from `start` (the model the
// device has now). Fails when fewer than 30 residuals are usable (too few frames with three
// tags or more).
Result<BoardFit> fit_board_calibration(const Camera& camera, const TagBundle& board,
                                       const std::vector<BoardFrame>& frames, const CornerNoiseModel& start,
                                       double ambiguity_chi2 = 40.0);

// The consistency of `frames` under `model` (as reported before and after the fit).
BoardConsistency board_consistency(const Camera& camera, const TagBundle& board,
                                   const std::vector<BoardFrame>& frames, const CornerNoiseModel& model,
                                   double ambiguity_chi2 = 40.0);

}  // namespace covtrack::fiducial
