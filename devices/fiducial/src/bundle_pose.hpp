#pragma once
// One pose for a rigid set of tags (a board, an object carrying several tags) from all
// visible corners of its tags, with its covariance, and a check that the tags agree.
//
// The corners are those each tag's own pose was fitted to (TagPose::corners_px: corrected,
// undistorted), each tag with its full 8x8 corner covariance Sigma_i. Of its systematic
// terms, each edge's placement and turn are the tag's own, while its apparent scale comes
// from the frame's image formation and is one error for all the frame's tags (s_i:
// TagPose::apparent_scale_px). The bundle's corner covariance is therefore
//   Sigma = blockdiag(Sigma_i - s_i s_i^T) + s s^T,   s = (s_1, ..., s_n) stacked,
// and the bundle pose minimises r^T Sigma^-1 r, r the stacked corners_i -
// project(T_camera_bundle T_bundle_tag_i X_k), by Gauss-Newton on the BODY perturbation,
// started from the tag pose (either solution of any tag, mapped to the bundle) that fits
// all corners best. Covariance (J^T Sigma^-1 J)^-1 with the stacked Jacobian J. With one
// tag in view the bundle pose is that tag's pose (its covariance and ambiguity test
// included), mapped to the bundle frame.
//
// Ambiguity (two tags or more): Gauss-Newton also runs from every other start; a distinct
// minimum whose corners are within `ambiguity_chi2` of the best one's (under Sigma) is
// covered by adding s s^T (s = other (-) best), as for one tag.
//
// Agreement (two tags or more): each tag's own pose (the nearer of its two solutions) is
// compared with where the other tags put it, chi2 = e^T (C_tag + A C_others A^T)^-1 e on
// 6 degrees of freedom (A maps a bundle perturbation to the tag's frame). The two
// estimates share no corner, only the frame's apparent scale, whose correlation the test
// leaves out: the others' fit, which models it as shared, hardly moves with it (measured:
// mean chi2 6.03 without, 6.04 with, on corners drawn from the model). Above
// `consistency_chi2` the tag disagrees and the bundle is DEGRADED:
//  - while a strict majority of the tags in view still remains without it, the worst
//    such tag is left out and the rest refitted (the pose and covariance of the agreeing
//    tags: a tag moved on its board, or a false detection, does not pull the pose);
//  - when no tag can be left out (two tags, or no majority left), the covariance grows by
//    (C_others - C) + d d^T per disagreeing tag (d = others' pose (-) bundle pose), so
//    that it covers the pose the other tags give without it, whichever side is wrong.
// devices/fiducial/README.md, "Tag bundles".
#include <string>
#include <vector>

#include "covtrack/protocol/camera_opencv.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"
#include "tag_pose.hpp"

namespace covtrack::fiducial {

struct BundleTag {
  int id = 0;
  double size_m = 0.1;
  Pose T_bundle_tag = Pose::Identity();
};

struct TagBundle {
  std::string name;  // its sensor name
  std::vector<BundleTag> tags;
  bool publish_tags = false;  // also publish each of its tags as tag<id>
};

// One of the bundle's tags as posed on its own in this frame.
struct BundleObservation {
  BundleTag tag;
  TagPose pose;
};

// How one tag's own pose agrees with where the bundle's other tags put it.
struct TagAgreement {
  int id = 0;
  double chi2 = 0;       // on 6 degrees of freedom
  double offset_m = 0;   // between the two poses of the tag's centre
  double offset_rad = 0; // between their orientations
};

struct BundlePose {
  Pose T_camera_bundle = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // BODY convention, inflation included
  std::vector<int> ids;            // the tags it was solved from
  std::vector<int> left_out;       // the tags in view left out as disagreeing
  bool ambiguous = false;          // inflated to cover a second pose
  double ambiguity_chi2 = 0;       // the second pose's corners' Mahalanobis^2; inf without one
  std::vector<TagAgreement> agreement;  // per tag in view (two tags or more), worst first
  bool disagree = false;           // a tag is above consistency_chi2: left out or covered
  std::string why_degraded;        // empty unless ambiguous or disagree
  bool degraded() const { return ambiguous || disagree; }
};

// `observations` holds the bundle's tags posed in this frame (at least one). The default
// limit of agreement is measured (devices/fiducial/README.md, "Tag bundles"): the
// 6-dof chi-square's 99.9% quantile, 22.5, called 11% of consistent rendered bundles
// DEGRADED, as single tags' own covariances have heavier tails than the model's.
Result<BundlePose> estimate_bundle_pose(const Camera& camera, const std::vector<BundleObservation>& observations,
                                        double ambiguity_chi2 = 40.0, double consistency_chi2 = 40.0);

// The pose from all of `observations`' corners by Gauss-Newton from `start`, with its
// covariance, and nothing else: no search for a second minimum, no agreement check. For
// fits repeated from a known good start (the calibration leaves each tag out in turn).
Result<BundlePose> refine_bundle_pose(const Camera& camera, const std::vector<BundleObservation>& observations,
                                      const Pose& start);

// The observations with each tag's apparent-scale error taken as its own, not the frame's
// (TagPose::apparent_scale_px cleared): the bundle's corner covariance is then
// block-diagonal. For a fit whose model has no correlation between tags (board_calibration).
std::vector<BundleObservation> with_own_scales(std::vector<BundleObservation> observations);

}  // namespace covtrack::fiducial
