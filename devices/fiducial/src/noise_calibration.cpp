#include "covtrack/devices/fiducial/noise_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

#include <Eigen/Dense>

#include "covtrack/devices/fiducial/tag_pose.hpp"

namespace covtrack::fiducial {
namespace {

Pose jittered(const CalibrationView& v, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Vec6 xi;
  for (int i = 0; i < 3; ++i) xi[i] = u(rng) * v.jitter_m, xi[i + 3] = u(rng) * v.jitter_rad;
  return v.tag.T_camera_tag * se3_exp(xi);
}

ViewDraw one_draw(const CameraModel& camera, TagDetector& detector, const CalibrationView& view,
                  std::mt19937_64& rng) {
  ViewDraw d;
  RenderedTag tag = view.tag;
  tag.T_camera_tag = d.T_camera_tag_true = jittered(view, rng);
  const cv::Mat frame =
      add_sensor_noise(render_tags(camera, detector.family(), {tag}, view.look), view.noise_sigma, rng);
  for (const Detection& det : detector.detect(frame))
    if (det.id == tag.id) d.detection = det;
  if (!d.detection) return d;
  d.image_noise = estimate_image_noise(frame);
  d.contrast = tag_contrast(frame, d.detection->corners_px, detector.family().cells_across_border());
  d.edge_length_px = mean_edge_length_px(d.detection->corners_px);
  d.axis_alignment = edge_axis_alignment(d.detection->corners_px);
  const auto truth = projected_corners(camera, tag);
  const auto& c = d.detection->corners_px;
  const cv::Point2d centre = (c[0] + c[1] + c[2] + c[3]) / 4.0;
  std::array<cv::Point2d, 4> radial, error;
  for (int k = 0; k < 4; ++k) {
    radial[k] = c[k] - centre;
    radial[k] /= std::max(std::hypot(radial[k].x, radial[k].y), 1e-9);
    error[k] = c[k] - truth[k];
    d.radial_error_px += error[k].dot(radial[k]) / 4;
  }
  for (int k = 0; k < 4; ++k) {
    const cv::Point2d e = error[k] - d.radial_error_px * radial[k];
    d.corner_sq_error_px2 += e.dot(e) / 8;
  }
  return d;
}

}  // namespace

Result<std::vector<ViewDraw>> draw_view(const CameraModel& camera, const DetectorOptions& options,
                                        const CalibrationView& view, int draws,
                                        std::uint64_t seed, int threads) {
  threads = std::max(1, threads);
  std::vector<std::unique_ptr<TagDetector>> detectors;
  for (int t = 0; t < threads; ++t) {
    auto d = TagDetector::create(options);
    if (!d) return std::unexpected(d.error());
    detectors.push_back(std::move(*d));
  }
  std::vector<ViewDraw> out(static_cast<std::size_t>(std::max(draws, 0)));
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t)
    workers.emplace_back([&, t] {
      for (int i = t; i < draws; i += threads) {
        std::mt19937_64 rng(seed * 1000003u + static_cast<std::uint64_t>(i));
        out[static_cast<std::size_t>(i)] = one_draw(camera, *detectors[t], view, rng);
      }
    });
  for (auto& w : workers) w.join();
  return out;
}

CornerNoise corner_noise(const CornerNoiseModel& model, const ViewDraw& d) {
  return {model.sigma_px(d.image_noise, d.contrast, d.edge_length_px, d.axis_alignment),
          model.radial_bias_px, model.radial_sigma_px};
}

double mean_pose_nees(const CameraModel& camera, const CalibrationView& view,
                      const std::vector<ViewDraw>& draws, const CornerNoiseModel& model, int* count) {
  double sum = 0;
  int n = 0;
  for (const ViewDraw& d : draws) {
    if (!d.detection) continue;
    auto pose = estimate_tag_pose(camera, d.detection->corners_px, view.tag.size_m,
                                  corner_noise(model, d));
    if (!pose) continue;
    const Vec6 e = boxminus(d.T_camera_tag_true, pose->best.T_camera_tag);
    sum += e.dot(pose->covariance.ldlt().solve(e));
    ++n;
  }
  if (count) *count = n;
  return n ? sum / n : 0;
}

namespace {

using Vec3 = Eigen::Vector3d;

// Per view: y = mean squared corner error, x = mean of each model term; y = sum c_k x_k,
// solved for c_k >= 0 in relative least squares.
Vec3 fit_terms(const std::vector<std::vector<ViewDraw>>& views) {
  std::vector<Vec3> xs;
  std::vector<double> ys;
  for (const auto& draws : views) {
    Vec3 x = Vec3::Zero();
    double y = 0;
    int n = 0;
    for (const ViewDraw& d : draws) {
      if (!d.detection) continue;
      x += Vec3(1, CornerNoiseModel::noise_term(d.image_noise, d.contrast, d.edge_length_px),
                d.axis_alignment);
      y += d.corner_sq_error_px2;
      ++n;
    }
    if (n) xs.push_back(x / n), ys.push_back(y / n);
  }
  std::array<bool, 3> used{true, true, true};
  Vec3 c = Vec3::Zero();
  for (int round = 0; round < 3; ++round) {
    std::vector<int> cols;
    for (int k = 0; k < 3; ++k)
      if (used[k]) cols.push_back(k);
    if (cols.empty() || xs.empty()) break;
    Eigen::MatrixXd A(static_cast<Eigen::Index>(xs.size()), static_cast<Eigen::Index>(cols.size()));
    Eigen::VectorXd b = Eigen::VectorXd::Ones(A.rows());
    for (Eigen::Index i = 0; i < A.rows(); ++i)
      for (std::size_t j = 0; j < cols.size(); ++j)
        A(i, static_cast<Eigen::Index>(j)) = xs[static_cast<std::size_t>(i)][cols[j]] / std::max(ys[static_cast<std::size_t>(i)], 1e-12);
    const Eigen::VectorXd p = A.colPivHouseholderQr().solve(b);
    c.setZero();
    bool negative = false;
    for (std::size_t j = 0; j < cols.size(); ++j) {
      if (p(static_cast<Eigen::Index>(j)) < 0) used[cols[j]] = false, negative = true;
      else c[cols[j]] = p(static_cast<Eigen::Index>(j));
    }
    if (!negative) break;
  }
  return c;
}

}  // namespace

CornerNoiseModel fit_corner_noise(const CameraModel& camera, const std::vector<CalibrationView>& views,
                                  const std::vector<std::vector<ViewDraw>>& draws) {
  const Vec3 c = fit_terms(draws);
  CornerNoiseModel m;
  m.floor_px = std::sqrt(c[0]), m.gain_px = std::sqrt(c[1]), m.aligned_px = std::sqrt(c[2]);
  double sum = 0, sq = 0;
  int n = 0;
  for (const auto& view : draws)
    for (const ViewDraw& d : view)
      if (d.detection) sum += d.radial_error_px, sq += d.radial_error_px * d.radial_error_px, ++n;
  if (n > 1) {
    m.radial_bias_px = sum / n;
    m.radial_sigma_px = std::sqrt(std::max(0.0, sq / n - m.radial_bias_px * m.radial_bias_px));
  }
  for (int round = 0; round < 3; ++round) {
    double sum = 0;
    int total = 0;
    for (std::size_t v = 0; v < views.size() && v < draws.size(); ++v) {
      int n = 0;
      const double mean = mean_pose_nees(camera, views[v], draws[v], m, &n);
      sum += mean * n, total += n;
    }
    if (total == 0 || sum <= 0) break;
    // NEES scales as 1 / sigma^2.
    const double f = std::sqrt(sum / total / 6.0);
    m.floor_px *= f, m.gain_px *= f, m.aligned_px *= f, m.radial_sigma_px *= f;
  }
  return m;
}

}  // namespace covtrack::fiducial
