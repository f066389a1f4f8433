#pragma once
// Projection of an object's vertex to the screen with its 2x2 pixel covariance, given the
// uncertain pose T_camera_object in the BODY convention: T_true = T * Exp(xi),
// xi ~ N(0, C), xi = [translation, rotation] (protocol/README.md).
//
// Two methods: the unscented transform over xi (dissertation appendix A,
// docs/background.md; the default) and the first-order linearisation (the fast path).
// Problems are reported in flags, never hidden.
#include <numbers>
#include <span>
#include <vector>

#include "covtrack/client/camera.hpp"
#include "covtrack/client/uncertain_pose.hpp"

namespace covtrack::client {

using Mat26 = Eigen::Matrix<double, 2, 6>;

// Scaled unscented transform (Julier): lambda = alpha^2 (n + kappa) - n, n = 6.
// The defaults (alpha 1, beta 0, kappa 0, SigmaRoot::automatic) were chosen by
// measurement against Monte Carlo (200,000 draws; pixel covariance of every vertex,
// relative Frobenius error; 4 objects from 0.6 to 2.7 m, a stylus among them, each with
// a diagonal and five correlated covariances). Worst error at 10 degrees of rotation sigma:
//   Cholesky root, kappa 3 - n (the dissertation's plain UT) 7.1%; Cholesky, kappa 0 6.0%;
//   principal axes, kappa -1 4.3%; symmetric root, kappa -1 / -0.5 / 0 / 0.5:
//   2.5 / 2.4 / 2.4 / 2.9%; beta 1 or 2 worse.
// Up to 3 degrees the roots agree to the Monte Carlo's own noise (Cholesky / symmetric
// with kappa 0: 0.67 / 0.69% at 2 degrees, 0.69 / 0.60% at 3, 1.0 / 0.62% at 4, 1.6 /
// 0.76% at 5). On held-out poses (tests/client/projection_test.cpp) the order is the other
// way (Cholesky / symmetric: 0.40 / 0.46% at 2 degrees, 0.64 / 0.77% at 5), so the default
// takes the cheapest root, Cholesky, wherever the unscented transform is used: within 2%
// on both sets, without an eigen decomposition per object.
// kappa 0 also makes every weight positive (W0 = 0): the covariance is never indefinite.
// On held-out poses the worst at 10 degrees is 2.1% (Cholesky) or 3.4% (symmetric), against
// 5.3% for the plain UT: so above 5 degrees the default takes a fifth-degree cubature rule
// instead (kCubatureMinRotationTraceRad2), 0.47% there.
// The matrix square root S (S S^T = (n + lambda) C) whose columns give the sigma points.
enum class SigmaRoot {
  automatic,  // Cholesky (a singular covariance: the principal root); the cubature rule
              // takes over above 5 degrees (UnscentedParams)
  cholesky,   // lower triangular: the cheapest
  principal,  // V sqrt(D): along the covariance's principal axes
  symmetric,  // V sqrt(D) V^T: the symmetric root, an eigen decomposition per object
};

// UnscentedParams' default bound above which the fifth-degree cubature rule (73 points,
// projection.cpp) replaces the unscented transform: 5 degrees on each axis. Worst error on
// six held-out correlated poses (projection_test), unscented / cubature: 0.77 / 0.41% at
// 5 degrees, 1.5 / 0.44% at 7, 3.4 / 0.47% at 10, 4.9 / 0.49% at 12 (the cubature's
// figures are the 400,000-draw Monte Carlo's own noise). Below the bound the cheaper rule
// is as good as its reference can tell at 2-3 degrees and within 1% up to 5.
inline constexpr double kCubatureMinRotationTraceRad2 =
    3 * (5.0 * std::numbers::pi / 180) * (5.0 * std::numbers::pi / 180);

struct UnscentedParams {
  double alpha = 1.0;
  double beta = 0.0;
  double kappa = 0.0;
  SigmaRoot root = SigmaRoot::automatic;
  // Poses whose rotation block's trace is above this take the fifth-degree cubature rule
  // instead of the sigma points above (infinity: never).
  double cubature_min_rotation_trace_rad2 = kCubatureMinRotationTraceRad2;
};

enum class ProjectionMethod { unscented, linear };

// ProjectionOptions::max_depth_sigma_ratio's default (see there).
inline constexpr double kDefaultMaxDepthSigmaRatio = 0.07;

struct ProjectionOptions {
  ProjectionMethod method = ProjectionMethod::unscented;
  UnscentedParams unscented;
  // Points closer than this (camera z, metres) have no usable pixel.
  double near_m = 0.01;
  // Above this rotation sigma (sqrt of the largest eigenvalue of the rotation block), a
  // Gaussian ellipse on the screen no longer describes where the vertex can be.
  double max_rotation_sigma_rad = 15.0 * std::numbers::pi / 180.0;
  // Add the camera's intrinsic sigmas (first order) to the screen covariance.
  bool add_intrinsic_uncertainty = true;
  // Above this depth sigma over depth (ProjectedVertex::depth_sigma_m / depth_m), the
  // perspective division bends too much over the vertex's spread along the line of sight
  // for a Gaussian through the unscented transform (or a linearisation) to describe its
  // pixel: flagged depth_nonlinear. Chosen by measurement (projection_test.cpp,
  // DepthNonlinearity): there the unscented covariance's error against Monte Carlo
  // passes 5%.
  double max_depth_sigma_ratio = kDefaultMaxDepthSigmaRatio;
};

struct ProjectionFlags {
  bool behind_camera = false;              // the vertex itself has z < near: no pixel
  bool sigma_point_behind_camera = false;  // a perturbed vertex has z < near
  bool rotation_too_uncertain = false;     // see max_rotation_sigma_rad
  bool unbounded = false;                  // input pose is LOST: covariance meaningless
  bool covariance_repaired = false;        // UT gave an indefinite matrix; clipped to PSD
  // The vertex, or one of its sigma points, lies past the lens model's distortion fold
  // (Camera::distortion_fold_r2): its pixel is not where the point appears.
  bool past_distortion_fold = false;
  // A NaN or an infinity in the pose, its covariance or the vertex, or numbers so large
  // that the pixel or its covariance overflowed: the vertex has no pixel.
  bool not_finite = false;
  // The vertex's depth spread along the line of sight is a large fraction of its depth
  // (ProjectionOptions::max_depth_sigma_ratio): the ellipse is an approximation to doubt.
  // A warning: the regions are still computed.
  bool depth_nonlinear = false;

  // The mean and covariance describe the vertex (the other flags are warnings).
  bool usable() const {
    return !behind_camera && !sigma_point_behind_camera && !unbounded && !past_distortion_fold && !not_finite;
  }
  bool any() const {
    return behind_camera || sigma_point_behind_camera || rotation_too_uncertain ||
           unbounded || covariance_repaired || past_distortion_fold || not_finite || depth_nonlinear;
  }
  // Inline: it runs for every vertex of every object, and a call cost more than the ors.
  ProjectionFlags& operator|=(const ProjectionFlags& o) {
    behind_camera |= o.behind_camera;
    sigma_point_behind_camera |= o.sigma_point_behind_camera;
    rotation_too_uncertain |= o.rotation_too_uncertain;
    unbounded |= o.unbounded;
    covariance_repaired |= o.covariance_repaired;
    past_distortion_fold |= o.past_distortion_fold;
    not_finite |= o.not_finite;
    depth_nonlinear |= o.depth_nonlinear;
    return *this;
  }
};

struct ProjectedVertex {
  Vec2 mean_px = Vec2::Zero();
  Mat2 covariance_px2 = Mat2::Zero();
  double depth_m = 0;  // camera z of the unperturbed vertex
  // Standard deviation of the camera z under the pose's error (the unscented transform's,
  // or first order); 0 without a covariance.
  double depth_sigma_m = 0;
  ProjectionFlags flags;
};

// d(pixel)/d(xi) at xi = 0 for the pixel of T * Exp(xi) * p_object; exact, analytic:
// J_camera(p_c) * R * [I, -skew(p_object)].
Mat26 pixel_jacobian_wrt_perturbation(const Camera& camera, const Pose& T_camera_object,
                                      const Vec3& p_object);

ProjectedVertex project_vertex(const Camera& camera, const UncertainPose& T_camera_object,
                               const Vec3& p_object, const ProjectionOptions& options = {});

// All vertices of one object; the UT sigma poses are built once and shared.
std::vector<ProjectedVertex> project_vertices(const Camera& camera,
                                              const UncertainPose& T_camera_object,
                                              std::span<const Vec3> p_object,
                                              const ProjectionOptions& options = {});
// The same into `out` (cleared first): a caller projecting every frame keeps one vector
// per object and pays no allocation once its capacity suffices.
void project_vertices(const Camera& camera, const UncertainPose& T_camera_object,
                      std::span<const Vec3> p_object, const ProjectionOptions& options,
                      std::vector<ProjectedVertex>& out);

}  // namespace covtrack::client
