#include "tag_pose.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <fmt/format.h>
#include <opencv2/calib3d.hpp>

#include "lens_edge_bend.hpp"

namespace covtrack::fiducial {
namespace {

// A corner this close to the frame's edge has the white margin beyond its edges cut off,
// and AprilTag's edge fit then goes astray (measured: a tag whose corner was ~5 px from
// the top of a 1280x720 frame was tilted 0.1 rad, 30 sigma, by fiducial_coplanar_test).
constexpr double kImageMarginPx = 8;

// The step s of a corner with n_a . s = ra and n_b . s = rb (the corner of edges a and b,
// their lines moved out by ra and rb); zero where the edges are parallel.
cv::Point2d corner_step(const cv::Point2d& na, const cv::Point2d& nb, double ra, double rb) {
  const double det = na.cross(nb);
  if (std::abs(det) < 1e-9) return {0, 0};
  return {(ra * nb.y - rb * na.y) / det, (rb * na.x - ra * nb.x) / det};
}

Pose pose_of(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Pose T = Pose::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = R.at<double>(r, c);
    T.translation()[r] = tvec.at<double>(r);
  }
  return T;
}

double sse(const Camera& cam, const Pose& T, const std::array<Vec3, 4>& object,
           const std::vector<cv::Point2d>& image) {
  double s = 0;
  for (int i = 0; i < 4; ++i) {
    const Vec3 p = T * object[i];
    if (p.z() <= 0) return std::numeric_limits<double>::infinity();
    const cv::Point2d d = pinhole_pixel(cam, p) - image[i];
    s += d.dot(d);
  }
  return s;
}

}  // namespace

// AprilTag 3's corner order, which is also the order SOLVEPNP_IPPE_SQUARE requires.
std::array<Vec3, 4> tag_corner_points(double size_m) {
  const double h = size_m / 2;
  return {Vec3(-h, h, 0), Vec3(h, h, 0), Vec3(h, -h, 0), Vec3(-h, -h, 0)};
}

std::array<cv::Point2d, 4> edge_outward_normals(const std::array<cv::Point2d, 4>& c) {
  const cv::Point2d centre = (c[0] + c[1] + c[2] + c[3]) / 4.0;
  std::array<cv::Point2d, 4> normal;
  for (std::size_t e = 0; e < 4; ++e) {
    const cv::Point2d d = c[(e + 1) % 4] - c[e];
    cv::Point2d n(d.y, -d.x);
    n /= std::max(std::hypot(n.x, n.y), 1e-12);
    normal[e] = n.dot(c[e] - centre) < 0 ? -n : n;
  }
  return normal;
}

std::array<cv::Point2d, 4> move_edges_in(const std::array<cv::Point2d, 4>& c,
                                         const EdgeShifts& shift_px) {
  const auto normal = edge_outward_normals(c);
  std::array<cv::Point2d, 4> out = c;
  for (std::size_t k = 0; k < 4; ++k) {
    // Corner k lies on edges a = k - 1 (which ends there) and b = k (which starts there).
    const std::size_t a = (k + 3) % 4, b = k;
    out[k] += corner_step(normal[a], normal[b], -shift_px[a][1], -shift_px[b][0]);
  }
  return out;
}

Eigen::Matrix<double, 8, 8> edge_line_modes(const std::array<cv::Point2d, 4>& c) {
  Eigen::Matrix<double, 8, 8> M;
  for (std::size_t e = 0; e < 4; ++e)
    for (const bool turn : {false, true}) {
      EdgeShifts inward{};  // move_edges_in moves edges in: a negative shift moves one out
      inward[e] = {-1.0, turn ? 1.0 : -1.0};
      const auto moved = move_edges_in(c, inward);
      const auto column = static_cast<Eigen::Index>(e + (turn ? 4 : 0));
      for (std::size_t k = 0; k < 4; ++k) {
        const cv::Point2d step = moved[k] - c[k];
        M(static_cast<Eigen::Index>(2 * k), column) = step.x;
        M(static_cast<Eigen::Index>(2 * k + 1), column) = step.y;
      }
    }
  return M;
}

Eigen::Matrix<double, 8, 1> apparent_scale_mode(const std::array<cv::Point2d, 4>& c, const CornerNoise& noise) {
  return noise.scale_sigma_px * edge_line_modes(c).leftCols<4>().rowwise().sum();
}

Eigen::Matrix<double, 8, 8> corner_covariance(const std::array<cv::Point2d, 4>& c, const CornerNoise& noise) {
  const Eigen::Matrix<double, 8, 8> M = edge_line_modes(c);
  Eigen::Matrix<double, 8, 8> edges = Eigen::Matrix<double, 8, 8>::Zero();
  edges.topLeftCorner<4, 4>() = noise.edge_sigma_px * noise.edge_sigma_px * Eigen::Matrix4d::Identity() +
                                noise.scale_sigma_px * noise.scale_sigma_px * Eigen::Matrix4d::Ones();
  edges.bottomRightCorner<4, 4>() = noise.tilt_sigma_px * noise.tilt_sigma_px * Eigen::Matrix4d::Identity();
  const double line2 = noise.line_sigma_px * noise.line_sigma_px;
  edges.topLeftCorner<4, 4>().diagonal().array() += line2 / 4;
  edges.bottomRightCorner<4, 4>().diagonal().array() += 3 * line2 / 4;
  for (int e = 0; e < 4; ++e) {
    const auto k = static_cast<std::size_t>(e);
    edges(e, e) += noise.locked_edge_px[k] * noise.locked_edge_px[k];
    edges(4 + e, 4 + e) += noise.locked_tilt_px[k] * noise.locked_tilt_px[k];
  }
  Eigen::Matrix<double, 8, 8> cov = M * edges * M.transpose();
  for (int i = 0; i < 8; ++i) {
    const double extra = noise.extra_px[static_cast<std::size_t>(i / 2)];
    cov(i, i) += noise.sigma_px * noise.sigma_px + extra * extra;
  }
  return cov;
}

Eigen::Matrix<double, 2, 6> point_jacobian(const Camera& cam, const Pose& T, const Vec3& X) {
  const Vec3 p = T * X;
  // T Exp(xi) X ~ T (X + rho + phi x X): dp/dxi = R [I, -[X]x].
  const Mat3 R = T.rotation();
  Eigen::Matrix<double, 3, 6> dp;
  dp << R, -R * skew(X);
  Eigen::Matrix<double, 2, 3> du;
  const double iz = 1 / p.z();
  du << cam.fx * iz, 0, -cam.fx * p.x() * iz * iz, 0, cam.fy * iz, -cam.fy * p.y() * iz * iz;
  return du * dp;
}

CornerJacobian corner_jacobian(const Camera& cam, const Pose& T, double size_m) {
  CornerJacobian J;
  const auto corners = tag_corner_points(size_m);
  for (int i = 0; i < 4; ++i) J.block<2, 6>(2 * i, 0) = point_jacobian(cam, T, corners[i]);
  return J;
}

Mat6 pose_covariance(const CornerJacobian& J, double sigma) {
  const Mat6 information = J.transpose() * J;
  Mat6 cov = information.ldlt().solve(Mat6::Identity()) * (sigma * sigma);
  return (cov + cov.transpose()) / 2;
}

Mat6 pose_covariance(const CornerJacobian& J, const Eigen::Matrix<double, 8, 8>& corner_covariance) {
  const Mat6 information = J.transpose() * corner_covariance.ldlt().solve(J);
  Mat6 cov = information.ldlt().solve(Mat6::Identity());
  return (cov + cov.transpose()) / 2;
}

Result<TagPose> estimate_tag_pose(const Camera& cam, const std::array<cv::Point2d, 4>& c,
                                  double size_m, const CornerNoise& noise, double ambiguity_chi2) {
  // Per corner coordinate (the line fit's ends carry all of its variance).
  const double sigma = std::hypot(noise.sigma_px, noise.line_sigma_px);
  for (const auto& p : c)
    if (!std::isfinite(p.x) || !std::isfinite(p.y))
      return fail("tag corner is not a finite number");
  if (!(size_m > 0) || !(sigma > 0)) return fail("tag size and corner sigma must be positive");
  if (cam.width_px > 0 && cam.height_px > 0)
    for (const auto& p : c)
      if (std::min({p.x, p.y, cam.width_px - 1 - p.x, cam.height_px - 1 - p.y}) < kImageMarginPx)
        return fail(fmt::format("tag corner ({:.1f}, {:.1f}) within {} px of the image's edge: the white "
                                "margin the edge fit needs is cut off",
                                p.x, p.y, kImageMarginPx));
  auto moved = move_edges_in(c, noise.edge_shift_px);
  const auto bend = straight_fit_corner_offsets(cam, moved);
  for (std::size_t k = 0; k < 4; ++k) moved[k] -= bend[k];
  std::vector<cv::Point2d> image(moved.begin(), moved.end());
  if (cam.has_distortion()) cv::undistortPoints(image, image, camera_matrix(cam), distortion_vector(cam), cv::noArray(), camera_matrix(cam));
  const double area = std::abs((image[2] - image[0]).cross(image[3] - image[1])) / 2;
  if (!(area > 4)) return fail(fmt::format("tag quad is degenerate (area {:.2f} px^2)", area));
  const Eigen::Matrix<double, 8, 8> corner_cov =
      corner_covariance({image[0], image[1], image[2], image[3]}, noise);

  const auto object = tag_corner_points(size_m);
  std::vector<cv::Point3d> obj;
  for (const Vec3& X : object) obj.emplace_back(X.x(), X.y(), X.z());
  const cv::Mat K(camera_matrix(cam));
  std::vector<cv::Mat> rvecs, tvecs;
  std::vector<PoseSolution> solutions, unrefined;
  try {
    cv::solvePnPGeneric(obj, image, K, cv::noArray(), rvecs, tvecs, false, cv::SOLVEPNP_IPPE_SQUARE);
    for (std::size_t i = 0; i < rvecs.size(); ++i) {
      const Pose ippe = pose_of(rvecs[i], tvecs[i]);
      cv::solvePnPRefineLM(obj, image, K, cv::noArray(), rvecs[i], tvecs[i]);
      const Pose T = pose_of(rvecs[i], tvecs[i]);
      const double e = sse(cam, T, object, image);
      if (std::isfinite(e)) solutions.push_back({T, e}), unrefined.push_back({ippe, sse(cam, ippe, object, image)});
    }
  } catch (const cv::Exception& e) {
    return fail(fmt::format("pose from tag corners failed: {}", e.what()));
  }
  if (solutions.empty()) return fail("no pose puts the tag in front of the camera");
  if (solutions.size() == 2 && boxminus(solutions[1].T_camera_tag, solutions[0].T_camera_tag).norm() < 1e-6) {
    // Near face-on both of IPPE's solutions can slide into one minimum under LM: the
    // tilt's sign is then still unknown, so the other solution is IPPE's own, unpolished
    // (the one farther from the polished pose).
    const auto far = [&](const PoseSolution& s) { return boxminus(s.T_camera_tag, solutions[0].T_camera_tag).norm(); };
    solutions[1] = far(unrefined[0]) > far(unrefined[1]) ? unrefined[0] : unrefined[1];
    solutions[1].sse_px2 = std::max(solutions[1].sse_px2, solutions[0].sse_px2);
  }
  std::sort(solutions.begin(), solutions.end(),
            [](const PoseSolution& a, const PoseSolution& b) { return a.sse_px2 < b.sse_px2; });

  TagPose out;
  out.best = solutions[0];
  out.corner_sigma_px = sigma;
  out.corners_px = {image[0], image[1], image[2], image[3]};
  out.corner_covariance = corner_cov;
  out.apparent_scale_px = apparent_scale_mode(out.corners_px, noise);
  // A pose's covariance from the corners', through the pinhole at that pose.
  const auto covariance_at = [&](const Pose& T) { return pose_covariance(corner_jacobian(cam, T, size_m), corner_cov); };
  out.covariance = covariance_at(out.best.T_camera_tag);
  out.ambiguity_chi2 = std::numeric_limits<double>::infinity();
  if (solutions.size() > 1) {
    out.second = solutions[1];
    // How far apart the two poses put the corners, in the corners' own uncertainty
    // (systematic terms included): what the data can tell apart.
    Eigen::Matrix<double, 8, 1> d;
    for (int i = 0; i < 4; ++i) {
      const cv::Point2d step = pinhole_pixel(cam, solutions[1].T_camera_tag * object[i]) -
                               pinhole_pixel(cam, out.best.T_camera_tag * object[i]);
      d(2 * i) = step.x, d(2 * i + 1) = step.y;
    }
    out.ambiguity_chi2 = d.dot(corner_cov.ldlt().solve(d));
    if (out.ambiguity_chi2 < ambiguity_chi2) {
      // The data cannot tell the two apart: cover the step to the other one, and the
      // other one's own uncertainty (taken to the best one's frame). Near face-on the truth
      // often lies between the two, off in directions that only the best one's
      // linearisation holds tight: with the step alone, 56 of 444 such poses had their
      // truth outside the 99% region, with both 6 (fiducial_ambiguity_test).
      const Vec6 step = boxminus(solutions[1].T_camera_tag, out.best.T_camera_tag);
      // T_second Exp(x) = T_best Exp(step) Exp(x) ~ T_best Exp(step + J_r(step)^-1 x).
      const Mat6 to_best = se3_right_jacobian(step).inverse();
      out.covariance += step * step.transpose() + to_best * covariance_at(solutions[1].T_camera_tag) * to_best.transpose();
      out.ambiguous = true;
    }
  }
  if (!out.covariance.allFinite()) return fail("pose covariance is not finite (degenerate view)");
  return out;
}

}  // namespace covtrack::fiducial
