#include "covtrack/devices/fiducial/noise_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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
    d.corner_sq_errors_px2[static_cast<std::size_t>(k)] = e.dot(e);
    d.corner_sq_error_px2 += e.dot(e) / 8;
  }
  d.corner_band_px = corner_quiet_band_px(c, detector.family().cells_across_border(),
                                          detector.family().quiet_cells(view.look.margin_cells));
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
          model.radial_bias_px, model.radial_sigma_px, model.narrow_sigmas_px(d.corner_band_px)};
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

using Vec4 = Eigen::Vector4d;

// The narrow-band term's exponents tried (variance ~ band^-power).
constexpr double kNarrowPowers[] = {2, 4, 6, 8, 10, 12};

// The model's four variance terms for one corner of one draw: sigma^2 = c . terms.
Vec4 terms_of(const CornerNoiseModel& shape, const ViewDraw& d, std::size_t corner) {
  const double narrow = CornerNoiseModel{0, 0, 0, 0, 0, 1, shape.narrow_power}.narrow_sigma_px(
      d.corner_band_px[corner]);
  return {1, CornerNoiseModel::noise_term(d.image_noise, d.contrast, d.edge_length_px),
          d.axis_alignment, narrow * narrow};
}

// A starting point: least squares of each view's mean squared corner error on the mean
// terms, relative residuals; a negative coefficient is dropped.
Vec4 initial_terms(const CornerNoiseModel& shape, const std::vector<std::vector<ViewDraw>>& views) {
  std::vector<Vec4> xs;
  std::vector<double> ys;
  for (const auto& draws : views) {
    Vec4 x = Vec4::Zero();
    double y = 0;
    int n = 0;
    for (const ViewDraw& d : draws) {
      if (!d.detection) continue;
      for (std::size_t k = 0; k < 4; ++k) x += terms_of(shape, d, k) / 4;
      y += d.corner_sq_error_px2;
      ++n;
    }
    if (n) xs.push_back(x / n), ys.push_back(y / n);
  }
  std::array<bool, 4> used{true, true, true, true};
  Vec4 c = Vec4::Zero();
  for (int round = 0; round < 4; ++round) {
    std::vector<int> cols;
    for (int k = 0; k < 4; ++k)
      if (used[static_cast<std::size_t>(k)]) cols.push_back(k);
    if (cols.empty() || xs.empty()) break;
    Eigen::MatrixXd A(static_cast<Eigen::Index>(xs.size()), static_cast<Eigen::Index>(cols.size()));
    Eigen::VectorXd b = Eigen::VectorXd::Ones(A.rows());
    for (Eigen::Index i = 0; i < A.rows(); ++i)
      for (std::size_t j = 0; j < cols.size(); ++j)
        A(i, static_cast<Eigen::Index>(j)) = xs[static_cast<std::size_t>(i)][cols[j]] /
                                             std::max(ys[static_cast<std::size_t>(i)], 1e-12);
    const Eigen::VectorXd p = A.colPivHouseholderQr().solve(b);
    c.setZero();
    bool negative = false;
    for (std::size_t j = 0; j < cols.size(); ++j) {
      if (p(static_cast<Eigen::Index>(j)) < 0) used[static_cast<std::size_t>(cols[j])] = false, negative = true;
      else c[cols[j]] = p(static_cast<Eigen::Index>(j));
    }
    if (!negative) break;
  }
  return c;
}

// Sum over views of log(view's corner NEES per coordinate)^2: a view 2x over-confident
// costs what a view 2x under-confident costs, and a few badly fitting views cannot pull
// every other one off as a pooled mean would.
double log_ratio_cost(const CornerNoiseModel& shape, const std::vector<std::vector<ViewDraw>>& views,
                      const Vec4& c) {
  double cost = 0;
  for (const auto& draws : views) {
    double sum = 0;
    int n = 0;
    for (const ViewDraw& d : draws) {
      if (!d.detection) continue;
      for (std::size_t k = 0; k < 4; ++k)
        sum += d.corner_sq_errors_px2[k] / 2 / std::max(c.dot(terms_of(shape, d, k)), 1e-12);
      n += 4;
    }
    if (n && sum > 0) cost += std::pow(std::log(sum / n), 2);
  }
  return cost;
}

// Coordinate search on each coefficient's logarithm, steps halving from a factor of 4;
// a coefficient may shrink to `tiny` (its term off). Returns the cost reached.
template <typename Vec, typename Cost>
double log_search(Vec& c, const Cost& cost_of, double tiny) {
  c = c.cwiseMax(tiny);
  double best = cost_of(c);
  for (double factor = 4; factor > 1.01; factor = std::sqrt(factor)) {
    for (bool improved = true; improved;) {
      improved = false;
      for (Eigen::Index k = 0; k < c.size(); ++k)
        for (double f : {factor, 1 / factor}) {
          Vec trial = c;
          trial[k] = std::max(trial[k] * f, tiny);
          const double cost = cost_of(trial);
          if (cost < best - 1e-12) best = cost, c = trial, improved = true;
        }
    }
  }
  return best;
}

// The four corner terms fitted in log ratio from the least-squares start.
Vec4 fit_terms(const CornerNoiseModel& shape, const std::vector<std::vector<ViewDraw>>& views,
               double* cost_out) {
  Vec4 c = initial_terms(shape, views);
  *cost_out = log_search(c, [&](const Vec4& t) { return log_ratio_cost(shape, views, t); }, 1e-8);
  return c;
}

}  // namespace

CornerNoiseModel fit_corner_noise(const CameraModel& camera, const std::vector<CalibrationView>& views,
                                  const std::vector<std::vector<ViewDraw>>& draws) {
  CornerNoiseModel m;
  Vec4 c = Vec4::Zero();
  double best = std::numeric_limits<double>::infinity();
  for (double power : kNarrowPowers) {
    CornerNoiseModel shape;
    shape.narrow_power = power;
    double cost = 0;
    const Vec4 trial = fit_terms(shape, draws, &cost);
    if (cost < best) best = cost, c = trial, m.narrow_power = power;
  }
  m.floor_px = std::sqrt(c[0]), m.gain_px = std::sqrt(c[1]), m.aligned_px = std::sqrt(c[2]);
  m.narrow_px = std::sqrt(c[3]);
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
    m.floor_px *= f, m.gain_px *= f, m.aligned_px *= f, m.radial_sigma_px *= f, m.narrow_px *= f;
  }
  return m;
}

}  // namespace covtrack::fiducial
