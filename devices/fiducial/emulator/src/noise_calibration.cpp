#include "covtrack/emulators/fiducial/noise_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <thread>
#include <tuple>
#include <utility>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <opencv2/calib3d.hpp>

#include "lens_edge_bend.hpp"
#include "tag_pose.hpp"

namespace covtrack::fiducial {
namespace {

constexpr double kGrossCornerErrorPx = 3;

Pose jittered(const CalibrationView& v, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Vec6 xi;
  for (int i = 0; i < 3; ++i) xi[i] = u(rng) * v.jitter_m, xi[i + 3] = u(rng) * v.jitter_rad;
  return v.tag.T_camera_tag * se3_exp(xi);
}

ViewDraw one_draw(TagDetector& detector, const CalibrationView& view, std::mt19937_64& rng) {
  const Camera& camera = view.camera;
  ViewDraw d;
  RenderedTag tag = view.tag;
  tag.T_camera_tag = d.T_camera_tag_true = jittered(view, rng);
  const cv::Mat frame = form_image(camera, detector.family(), {tag}, view.formation, rng);
  auto truth = projected_corners(camera, tag);
  const cv::Mat& lens = view.formation.true_distortion;
  if (!lens.empty() && cv::countNonZero(lens) > 0) {
    // Where the real lens puts them: through the true distortion, not the camera model's.
    std::vector<cv::Point3d> rays;
    for (const auto& p : truth) rays.emplace_back((p.x - camera.cx) / camera.fx, (p.y - camera.cy) / camera.fy, 1);
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix(camera), lens, truth);
  }
  for (std::size_t k = 0; k < 4; ++k) d.truth_px[k] = truth[k];
  // The detection of this tag, if any: the one nearest the truth with its id (a family
  // with few bits, such as tag16h5, also finds its id in the noise now and then), and
  // none if even that one is grossly off (a wrong quad: not what the noise model is for).
  double best = kGrossCornerErrorPx;
  for (const Detection& det : detector.detect(frame)) {
    if (det.id != tag.id) continue;
    double worst = 0;
    for (std::size_t k = 0; k < 4; ++k) worst = std::max(worst, cv::norm(det.corners_px[k] - d.truth_px[k]));
    if (worst < best) best = worst, d.detection = det;
  }
  if (d.detection) {
    d.inputs = measure_corner_inputs(frame, *d.detection, detector.family(), estimate_image_noise(frame));
    d.lens_bend_px = straight_fit_corner_offsets(camera, d.detection->corners_px);
  }
  return d;
}

// `count` detectors of o's family, kept for the calling thread's next views: making one
// builds the family's decode table, which for the large families (tagStandard52h13,
// tagCircle49h12) took longer than rendering and detecting a view's draws. At most four
// families are kept (a decode table can take tens of MB).
Result<std::vector<std::unique_ptr<TagDetector>>*> detectors_for(const DetectorOptions& o, int count) {
  constexpr std::size_t kFamiliesKept = 4;
  thread_local std::map<std::pair<std::string, int>, std::vector<std::unique_ptr<TagDetector>>> kept;
  const std::pair<std::string, int> key{o.family, o.max_hamming};
  if (!kept.contains(key) && kept.size() >= kFamiliesKept) kept.clear();
  auto& detectors = kept[key];
  while (static_cast<int>(detectors.size()) < count) {
    auto d = TagDetector::create(o);
    if (!d) return std::unexpected(d.error());
    detectors.push_back(std::move(*d));
  }
  for (auto& d : detectors)
    if (auto set = d->set_search(o); !set) return std::unexpected(set.error());
  return &detectors;
}

}  // namespace

Result<std::vector<ViewDraw>> draw_view(const DetectorOptions& options,
                                        const CalibrationView& view, int draws,
                                        std::uint64_t seed, int threads) {
  threads = std::max(1, threads);
  auto kept = detectors_for(options, threads);
  if (!kept) return std::unexpected(kept.error());
  auto& detectors = **kept;
  std::vector<ViewDraw> out(static_cast<std::size_t>(std::max(draws, 0)));
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t)
    workers.emplace_back([&, t] {
      for (int i = t; i < draws; i += threads) {
        std::mt19937_64 rng(seed * 1000003u + static_cast<std::uint64_t>(i));
        out[static_cast<std::size_t>(i)] = one_draw(*detectors[t], view, rng);
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
  auto c = move_edges_in(d.detection->corners_px, model.edge_shift_px(d.inputs));
  for (std::size_t k = 0; k < 4; ++k) c[k] -= d.lens_bend_px[k], out.error_px[k] = c[k] - d.truth_px[k];
  const auto normal = edge_outward_normals(c);
  for (std::size_t e = 0; e < 4; ++e) {
    const double start = out.error_px[e].dot(normal[e]), end = out.error_px[(e + 1) % 4].dot(normal[e]);
    out.edge_out_px[e] = (start + end) / 2, out.edge_turn_px[e] = (start - end) / 2;
  }
  return out;
}

void fit_locked_edges(CornerNoiseModel& m, const std::vector<std::vector<ViewDraw>>& views) {
  CornerNoiseModel unlocked = m;
  unlocked.locked_edge_px = unlocked.locked_tilt_px = 0;
  // Per edge of every draw: lock * (error^2 - the rest of the model's variance), and lock^2.
  double out_num = 0, turn_num = 0, den = 0, turn_den = 0;
  for (const auto& draws : views)
    for (const ViewDraw& d : draws) {
      if (!d.detection) continue;
      const auto& c = d.detection->corners_px;
      const CornerErrors errors = corner_errors(m, d);
      // The model's variance of each edge's outward error and turn: its corner covariance
      // in the edges' line modes (corner_errors reads them the same way).
      const Eigen::Matrix<double, 8, 8> to_edges = edge_line_modes(c).inverse();
      const Eigen::Matrix<double, 8, 8> modelled =
          to_edges * corner_covariance(c, corner_noise(unlocked, d)) * to_edges.transpose();
      for (std::size_t e = 0; e < 4; ++e) {
        const double lock = d.inputs.phase_lock[e];
        const auto i = static_cast<Eigen::Index>(e);
        out_num += lock * (errors.edge_out_px[e] * errors.edge_out_px[e] - modelled(i, i));
        const double turn_lock = d.inputs.turn_lock[e];
        turn_num += turn_lock * (errors.edge_turn_px[e] * errors.edge_turn_px[e] - modelled(4 + i, 4 + i));
        den += lock * lock, turn_den += turn_lock * turn_lock;
      }
    }
  if (den <= 0) return;
  m.locked_edge_px = std::sqrt(std::max(out_num / den, 0.0));
  m.locked_tilt_px = std::sqrt(std::max(turn_num / turn_den, 0.0));
}

std::string describe(const CornerNoiseModel& m) {
  return fmt::format("gain {:.4f}, floor {:.4f}, sample floor {:.4f}, aligned {:.4f}, shift {:.4f} (falloff {:.2f}, "
                     "sigma {:.4f}), scale bias {:.4f}/px blur, scale {:.4f} + {:.4f}/px blur, edge {:.4f} + {:.4f}/px "
                     "blur, tilt {:.4f} + {:.4f}/px blur, locked edge {:.4f} tilt {:.4f}",
                     m.gain_px, m.floor_px, m.sample_floor_px, m.aligned_px, m.shift_px, m.shift_falloff,
                     m.shift_sigma_px, m.scale_bias_per_blur, m.scale_sigma_px, m.scale_per_blur, m.edge_sigma_px,
                     m.edge_per_blur, m.tilt_sigma_px, m.tilt_per_blur, m.locked_edge_px, m.locked_tilt_px);
}

double mean_pose_nees(const CalibrationView& view,
                      const std::vector<ViewDraw>& draws, const CornerNoiseModel& model, int* count) {
  double sum = 0;
  int n = 0;
  for (const ViewDraw& d : draws) {
    if (!d.detection) continue;
    auto pose = estimate_tag_pose(view.camera, d.detection->corners_px, view.tag.size_m,
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

// The independent variance's terms: floor, image noise, axis alignment, white-cell shift
// residual, per-sample floor.
constexpr int kTerms = 5;
using Terms = Eigen::Matrix<double, kTerms, 1>;

// One corner of one draw, ready for the fit: its variance terms (sigma^2 = c . terms)
// and its squared error (radial part removed).
struct CornerSample {
  Terms terms;
  double sq_px2;
};

// A detected draw and its corner errors after the predicted shifts (stage 1's), which
// stages 2 and 3 both read: computed once.
struct DrawErrors {
  const ViewDraw* draw;
  CornerErrors errors;
};
using ErrorsByView = std::vector<std::vector<DrawErrors>>;

ErrorsByView errors_by_view(const CornerNoiseModel& model, const std::vector<std::vector<ViewDraw>>& views) {
  ErrorsByView out;
  for (const auto& draws : views) {
    auto& view = out.emplace_back();
    for (const ViewDraw& d : draws)
      if (d.detection) view.push_back({&d, corner_errors(model, d)});
  }
  return out;
}

// Each corner's error about its view's mean error for that corner: the draw-to-draw
// spread, which the independent terms model (the view's mean is the systematic terms').
std::vector<std::vector<CornerSample>> corner_samples(const CornerNoiseModel& model, const ErrorsByView& views) {
  std::vector<std::vector<CornerSample>> out;
  for (const auto& view : views) {
    auto& samples = out.emplace_back();
    const double n = static_cast<double>(view.size());
    if (n < 3) continue;
    std::array<cv::Point2d, 4> mean{};
    for (const DrawErrors& de : view)
      for (std::size_t k = 0; k < 4; ++k) mean[k] += de.errors.error_px[k] / n;
    for (const DrawErrors& de : view) {
      const CornerInputs& in = de.draw->inputs;
      const auto reach = model.edge_reach(in);
      const double noise = CornerNoiseModel::noise_term(in.image_noise, in.contrast, in.edge_length_px);
      for (std::size_t k = 0; k < 4; ++k) {
        const std::size_t a = (k + 3) % 4;  // corner k joins edges k - 1 and k
        const double r = reach[a] * reach[a] + reach[k] * reach[k];
        const cv::Point2d e = de.errors.error_px[k] - mean[k];
        Terms t;
        t << 1, noise, in.axis_alignment, r, CornerNoiseModel::sample_factor(in.edge_length_px);
        samples.push_back({t, e.dot(e) * n / (n - 1)});
      }
    }
  }
  return out;
}

// A starting point: least squares of each view's mean squared corner error on the mean
// terms, relative residuals; a negative coefficient is dropped.
Terms initial_terms(const std::vector<std::vector<CornerSample>>& views) {
  std::vector<Terms> xs;
  std::vector<double> ys;
  for (const auto& samples : views) {
    if (samples.empty()) continue;
    Terms x = Terms::Zero();
    double y = 0;
    for (const CornerSample& s : samples) x += s.terms, y += s.sq_px2 / 2;
    xs.push_back(x / samples.size()), ys.push_back(y / samples.size());
  }
  std::array<bool, kTerms> used{};
  used.fill(true);
  Terms c = Terms::Zero();
  for (int round = 0; round < kTerms; ++round) {
    std::vector<int> cols;
    for (int k = 0; k < kTerms; ++k)
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
double log_ratio_cost(const std::vector<std::vector<CornerSample>>& views, const Terms& c) {
  double cost = 0;
  for (const auto& samples : views) {
    double sum = 0;
    for (const CornerSample& s : samples) sum += s.sq_px2 / 2 / std::max(c.dot(s.terms), 1e-12);
    if (!samples.empty() && sum > 0) cost += std::pow(std::log(sum / samples.size()), 2);
  }
  return cost;
}

// Stage 1: each edge end's outward error against white * reach (the white cells' pull)
// and polarity * blur (the tone curve's), for falloffs on a grid; both amplitudes by
// least squares, the first kept non-negative.
void fit_edge_shift(CornerNoiseModel& m, const std::vector<std::vector<ViewDraw>>& views) {
  struct EdgeSample { double x2, white, signed_blur, shift; };
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
          edges.push_back({x * x, d.inputs.inner_white[e][end], d.inputs.polarity * d.inputs.blur_px,
                           (c[k] - d.lens_bend_px[k] - d.truth_px[k]).dot(normal[e])});
        }
      }
    }
  double best = std::numeric_limits<double>::infinity();
  for (double falloff = 0.02; falloff < 2; falloff += 0.01) {
    Eigen::Matrix2d AtA = Eigen::Matrix2d::Zero();
    Eigen::Vector2d Atb = Eigen::Vector2d::Zero();
    double bb = 0;
    for (const EdgeSample& s : edges) {
      const Eigen::Vector2d a(s.white * std::exp(-falloff * s.x2), s.signed_blur);
      AtA += a * a.transpose(), Atb += a * s.shift, bb += s.shift * s.shift;
    }
    if (AtA.determinant() <= 1e-12) continue;
    Eigen::Vector2d x = AtA.ldlt().solve(Atb);
    if (x[0] < 0) x = {0, Atb[1] / AtA(1, 1)};
    const double residual = bb - 2 * x.dot(Atb) + x.dot(AtA * x);
    if (residual < best) best = residual, m.shift_px = x[0], m.shift_falloff = falloff, m.scale_bias_per_blur = x[1];
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

// x * (floor^2 + (per_blur * blur)^2) through points (blur, variance, x) by non-negative
// least squares on [x, x blur^2] (x: how the spread scales with the view, 1 if it does not).
std::pair<double, double> fit_floor_and_growth(const std::vector<std::array<double, 3>>& points) {
  if (points.empty()) return {0, 0};
  Eigen::MatrixXd A(static_cast<Eigen::Index>(points.size()), 2);
  Eigen::VectorXd b(A.rows());
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const auto& [blur, variance, x] = points[static_cast<std::size_t>(i)];
    A(i, 0) = x, A(i, 1) = x * blur * blur, b(i) = variance;
  }
  Eigen::Vector2d c = A.colPivHouseholderQr().solve(b);
  // A negative coefficient: the other one alone.
  if (c[0] < 0) c = {0, std::max(0.0, A.col(1).dot(b) / A.col(1).squaredNorm())};
  if (c[1] < 0) c = {std::max(0.0, A.col(0).dot(b) / A.col(0).squaredNorm()), 0};
  return {std::sqrt(c[0]), std::sqrt(c[1])};
}

// Stage 3: each view's mean outward error per edge (after the edge shift's correction)
// splits into the four edges' common part and each edge's rest. Over views, the common
// part's mean square is scale_sigma^2 and the rest's is 3/4 of edge_sigma^2 (the common
// part took one quarter of each edge's own); each edge's mean turn (half its start's
// minus its end's error) has tilt_sigma^2. The means' sampling variance, from the
// draw-to-draw spread, is taken off. The edge and turn spreads are fitted at 64 px: each
// view's points weighted by CornerNoiseModel::size_factor of its mean edge length, squared.
void fit_systematic_terms(CornerNoiseModel& m, const ErrorsByView& views) {
  std::vector<std::array<double, 3>> scale_points, edge_points, tilt_points;
  for (const auto& view : views) {
    std::vector<CornerErrors> errors;
    double blur = 0, length = 0;
    for (const DrawErrors& de : view)
      if (std::isfinite(de.draw->inputs.blur_px))
        errors.push_back(de.errors), blur += de.draw->inputs.blur_px, length += de.draw->inputs.edge_length_px;
    const double n = static_cast<double>(errors.size());
    if (n < 3) continue;
    blur /= n, length /= n;
    const double x = std::pow(CornerNoiseModel::size_factor(length), 2);
    // Per edge: the mean over draws and the variance of one draw, of the outward error
    // (out) and the turn.
    std::array<double, 4> out{}, out_var{}, turn{}, turn_var{};
    for (const auto& e : errors)
      for (std::size_t k = 0; k < 4; ++k) out[k] += e.edge_out_px[k] / n, turn[k] += e.edge_turn_px[k] / n;
    for (const auto& e : errors)
      for (std::size_t k = 0; k < 4; ++k) {
        out_var[k] += (e.edge_out_px[k] - out[k]) * (e.edge_out_px[k] - out[k]) / (n - 1);
        turn_var[k] += (e.edge_turn_px[k] - turn[k]) * (e.edge_turn_px[k] - turn[k]) / (n - 1);
      }
    const double common = (out[0] + out[1] + out[2] + out[3]) / 4;
    const double mean_var = (out_var[0] + out_var[1] + out_var[2] + out_var[3]) / 4;
    scale_points.push_back({blur, common * common - mean_var / (4 * n), 1});
    double rest = 0, turn_sq = 0, turn_mean_var = 0;
    for (std::size_t k = 0; k < 4; ++k)
      rest += (out[k] - common) * (out[k] - common) / 4, turn_sq += turn[k] * turn[k] / 4,
          turn_mean_var += turn_var[k] / 4;
    edge_points.push_back({blur, (rest - 0.75 * mean_var / n) * 4 / 3, x});
    tilt_points.push_back({blur, turn_sq - turn_mean_var / n, x});
  }
  std::tie(m.scale_sigma_px, m.scale_per_blur) = fit_floor_and_growth(scale_points);
  std::tie(m.edge_sigma_px, m.edge_per_blur) = fit_floor_and_growth(edge_points);
  std::tie(m.tilt_sigma_px, m.tilt_per_blur) = fit_floor_and_growth(tilt_points);
}

}  // namespace

CornerNoiseModel fit_corner_noise(const std::vector<CalibrationView>& views,
                                  const std::vector<std::vector<ViewDraw>>& draws) {
  CornerNoiseModel m;
  fit_edge_shift(m, draws);
  const ErrorsByView errors = errors_by_view(m, draws);
  const auto samples = corner_samples(m, errors);
  Terms c = initial_terms(samples);
  log_search(c, [&](const Terms& t) { return log_ratio_cost(samples, t); }, 1e-8);
  m.floor_px = std::sqrt(c[0]), m.gain_px = std::sqrt(c[1]), m.aligned_px = std::sqrt(c[2]);
  m.shift_sigma_px = std::sqrt(c[3]), m.sample_floor_px = std::sqrt(c[4]);
  fit_systematic_terms(m, errors);
  // Stage 4 on the pooled NEES: with the systematic terms in the model a view's own mean
  // NEES is expected to scatter (its biases are one draw of them), so only the pool says
  // whether the spreads are right.
  for (int round = 0; round < 4; ++round) {
    double sum = 0;
    int n = 0;
    for (std::size_t v = 0; v < views.size() && v < draws.size(); ++v) {
      int count = 0;
      const double mean = mean_pose_nees(views[v], draws[v], m, &count);
      sum += mean * count, n += count;
    }
    if (n == 0 || sum <= 0) break;
    // NEES scales as 1 / sigma^2.
    const double f = std::sqrt(sum / n / 6.0);
    m.floor_px *= f, m.sample_floor_px *= f, m.gain_px *= f, m.aligned_px *= f, m.shift_sigma_px *= f;
    m.scale_sigma_px *= f, m.scale_per_blur *= f, m.edge_sigma_px *= f, m.edge_per_blur *= f;
    m.tilt_sigma_px *= f, m.tilt_per_blur *= f;
  }
  return m;
}

}  // namespace covtrack::fiducial
