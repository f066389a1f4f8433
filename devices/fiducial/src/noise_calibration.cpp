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
  d.inputs = measure_corner_inputs(frame, *d.detection, detector.family(), estimate_image_noise(frame));
  const auto truth = projected_corners(camera, tag);
  for (std::size_t k = 0; k < 4; ++k) d.truth_px[k] = truth[k];
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
  return model.noise(d.inputs);
}

CornerErrors corner_errors(const CornerNoiseModel& model, const ViewDraw& d) {
  CornerErrors out;
  if (!d.detection) return out;
  const auto c = move_edges_in(d.detection->corners_px, model.edge_shift_px(d.inputs));
  const cv::Point2d centre = (c[0] + c[1] + c[2] + c[3]) / 4.0;
  std::array<cv::Point2d, 4> radial;
  for (std::size_t k = 0; k < 4; ++k) {
    radial[k] = c[k] - centre;
    radial[k] /= std::max(std::hypot(radial[k].x, radial[k].y), 1e-9);
    out.error_px[k] = c[k] - d.truth_px[k];
    out.radial_px += out.error_px[k].dot(radial[k]) / 4;
  }
  for (std::size_t k = 0; k < 4; ++k) {
    const cv::Point2d e = out.error_px[k] - out.radial_px * radial[k];
    out.sq_px2[k] = e.dot(e);
  }
  return out;
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

// One corner of one draw, ready for the fit: its four variance terms (sigma^2 = c . terms)
// and its squared error (radial part removed).
struct CornerSample {
  Vec4 terms;
  double sq_px2;
};

std::vector<std::vector<CornerSample>> corner_samples(const CornerNoiseModel& model,
                                                      const std::vector<std::vector<ViewDraw>>& views) {
  std::vector<std::vector<CornerSample>> out;
  for (const auto& draws : views) {
    auto& samples = out.emplace_back();
    for (const ViewDraw& d : draws) {
      if (!d.detection) continue;
      const CornerErrors err = corner_errors(model, d);
      const auto reach = model.edge_reach(d.inputs);
      const double noise = CornerNoiseModel::noise_term(d.inputs.image_noise, d.inputs.contrast,
                                                        d.inputs.edge_length_px);
      for (std::size_t k = 0; k < 4; ++k) {
        const std::size_t a = (k + 3) % 4;  // corner k joins edges k - 1 and k
        const double r = reach[a] * reach[a] + reach[k] * reach[k];
        samples.push_back({Vec4(1, noise, d.inputs.axis_alignment, r), err.sq_px2[k]});
      }
    }
  }
  return out;
}

// A starting point: least squares of each view's mean squared corner error on the mean
// terms, relative residuals; a negative coefficient is dropped.
Vec4 initial_terms(const std::vector<std::vector<CornerSample>>& views) {
  std::vector<Vec4> xs;
  std::vector<double> ys;
  for (const auto& samples : views) {
    if (samples.empty()) continue;
    Vec4 x = Vec4::Zero();
    double y = 0;
    for (const CornerSample& s : samples) x += s.terms, y += s.sq_px2 / 2;
    xs.push_back(x / samples.size()), ys.push_back(y / samples.size());
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
double log_ratio_cost(const std::vector<std::vector<CornerSample>>& views, const Vec4& c) {
  double cost = 0;
  for (const auto& samples : views) {
    double sum = 0;
    for (const CornerSample& s : samples) sum += s.sq_px2 / 2 / std::max(c.dot(s.terms), 1e-12);
    if (!samples.empty() && sum > 0) cost += std::pow(std::log(sum / samples.size()), 2);
  }
  return cost;
}

// Stage 0: each edge end's outward error against white * reach, over falloffs on a grid;
// the amplitude by least squares through zero (no white cell inside, no shift).
void fit_edge_shift(CornerNoiseModel& m, const std::vector<std::vector<ViewDraw>>& views) {
  struct EdgeSample { double x2, white, shift; };
  std::vector<EdgeSample> edges;
  for (const auto& draws : views)
    for (const ViewDraw& d : draws) {
      if (!d.detection) continue;
      const auto& c = d.detection->corners_px;
      const auto normal = edge_outward_normals(c);
      for (std::size_t e = 0; e < 4; ++e) {
        const double x = d.inputs.border_px[e] / d.inputs.blur_px;
        if (!std::isfinite(x)) continue;
        for (std::size_t end = 0; end < 2; ++end) {
          const std::size_t k = (e + end) % 4;  // the edge's start or end corner
          edges.push_back({x * x, d.inputs.inner_white[e][end], (c[k] - d.truth_px[k]).dot(normal[e])});
        }
      }
    }
  double best = std::numeric_limits<double>::infinity();
  for (double falloff = 0.02; falloff < 2; falloff += 0.01) {
    double gg = 0, gs = 0, ss = 0;
    for (const EdgeSample& s : edges) {
      const double g = s.white * std::exp(-falloff * s.x2);
      gg += g * g, gs += g * s.shift, ss += s.shift * s.shift;
    }
    if (gg <= 0) continue;
    const double amplitude = std::max(0.0, gs / gg);
    const double residual = ss - 2 * amplitude * gs + amplitude * amplitude * gg;
    if (residual < best) best = residual, m.shift_px = amplitude, m.shift_falloff = falloff;
  }
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

}  // namespace

CornerNoiseModel fit_corner_noise(const CameraModel& camera, const std::vector<CalibrationView>& views,
                                  const std::vector<std::vector<ViewDraw>>& draws) {
  CornerNoiseModel m;
  fit_edge_shift(m, draws);
  double sum = 0, sq = 0;
  int n = 0;
  for (const auto& view : draws)
    for (const ViewDraw& d : view)
      if (d.detection) {
        const double r = corner_errors(m, d).radial_px;
        sum += r, sq += r * r, ++n;
      }
  if (n > 1) {
    m.radial_bias_px = sum / n;
    m.radial_sigma_px = std::sqrt(std::max(0.0, sq / n - m.radial_bias_px * m.radial_bias_px));
  }
  const auto samples = corner_samples(m, draws);
  Vec4 c = initial_terms(samples);
  log_search(c, [&](const Vec4& t) { return log_ratio_cost(samples, t); }, 1e-8);
  m.floor_px = std::sqrt(c[0]), m.gain_px = std::sqrt(c[1]), m.aligned_px = std::sqrt(c[2]);
  m.shift_sigma_px = std::sqrt(c[3]);
  // Stage 3 on the views' geometric mean NEES, as stage 2 weighs views in log ratio: the
  // pooled mean would be set by the few most over-confident views (face-on, edges along
  // the pixel axes) and leave every other view under-confident.
  for (int round = 0; round < 3; ++round) {
    double log_sum = 0;
    int views_used = 0;
    for (std::size_t v = 0; v < views.size() && v < draws.size(); ++v) {
      int n = 0;
      const double mean = mean_pose_nees(camera, views[v], draws[v], m, &n);
      if (n > 0 && mean > 0) log_sum += std::log(mean / 6.0), ++views_used;
    }
    if (views_used == 0) break;
    // NEES scales as 1 / sigma^2.
    const double f = std::exp(log_sum / views_used / 2);
    m.floor_px *= f, m.gain_px *= f, m.aligned_px *= f, m.radial_sigma_px *= f, m.shift_sigma_px *= f;
  }
  return m;
}

}  // namespace covtrack::fiducial
