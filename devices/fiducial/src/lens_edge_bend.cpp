#include "lens_edge_bend.hpp"

#include <cmath>
#include <vector>

#include <opencv2/calib3d.hpp>

namespace covtrack::fiducial {
namespace {

// AprilTag refines each edge from evenly spaced samples strictly between its corners.
constexpr int kSamplesPerEdge = 16;

struct Line {
  cv::Point2d point, direction;
};

// The least-squares line through the points (their centroid and principal direction).
Line fit_line(const std::vector<cv::Point2d>& p) {
  cv::Point2d c(0, 0);
  for (const auto& q : p) c += q / static_cast<double>(p.size());
  double xx = 0, xy = 0, yy = 0;
  for (const auto& q : p) {
    const cv::Point2d d = q - c;
    xx += d.x * d.x, xy += d.x * d.y, yy += d.y * d.y;
  }
  const double angle = 0.5 * std::atan2(2 * xy, xx - yy);
  return {c, {std::cos(angle), std::sin(angle)}};
}

cv::Point2d cross(const Line& a, const Line& b) {
  const double det = a.direction.cross(b.direction);
  if (std::abs(det) < 1e-12) return a.point;
  return a.point + a.direction * ((b.point - a.point).cross(b.direction) / det);
}

}  // namespace

std::array<cv::Point2d, 4> straight_fit_corner_offsets(const Camera& cam,
                                                       const std::array<cv::Point2d, 4>& corners_px) {
  std::array<cv::Point2d, 4> offsets{};
  if (!cam.has_distortion()) return offsets;
  // The corners on the ideal (pinhole) image, as normalised rays, where edges are straight.
  std::vector<cv::Point2d> distorted(corners_px.begin(), corners_px.end()), ideal;
  cv::undistortPoints(distorted, ideal, camera_matrix(cam), distortion_vector(cam));
  std::vector<cv::Point3d> rays;
  for (int e = 0; e < 4; ++e)
    for (int j = 1; j <= kSamplesPerEdge; ++j) {
      const double t = static_cast<double>(j) / (kSamplesPerEdge + 1);
      const cv::Point2d q = ideal[e] + t * (ideal[(e + 1) % 4] - ideal[e]);
      rays.emplace_back(q.x, q.y, 1);
    }
  for (const auto& q : ideal) rays.emplace_back(q.x, q.y, 1);
  std::vector<cv::Point2d> image;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix(cam), distortion_vector(cam), image);
  std::array<Line, 4> lines;
  for (int e = 0; e < 4; ++e)
    lines[static_cast<std::size_t>(e)] = fit_line({image.begin() + e * kSamplesPerEdge,
                                                   image.begin() + (e + 1) * kSamplesPerEdge});
  for (std::size_t k = 0; k < 4; ++k) {
    const cv::Point2d lens_corner = image[4 * kSamplesPerEdge + k];
    offsets[k] = cross(lines[(k + 3) % 4], lines[k]) - lens_corner;
  }
  return offsets;
}

}  // namespace covtrack::fiducial
