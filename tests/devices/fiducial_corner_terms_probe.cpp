// Run by hand (about 5 min; seconds with a cache): build/tests/devices/fiducial_corner_terms_probe [CACHE_DIR]
// or, for the phase-locked views alone: build/tests/devices/fiducial_corner_terms_probe --locked
// How well each term of the corner noise model matches the corner errors, by the tag's
// size in pixels, distance band, rasteriser, tone curve and camera, on the held-out check's calibration set and (for
// reporting only: nothing is fitted on it) its validation set. The model is the one the
// calibration fits (fit_corner_noise), as in fiducial_heldout_nees_test. Per term, the
// observed variance over the modelled one (1 when right): `indep` each corner's
// draw-to-draw spread, `scale` a view's mean common outward error of the four edges,
// `edge` each edge's own, `turn` each edge's mean turn (devices/fiducial/README.md). Then
// the pose NEES per principal direction of the pose covariance (tightest first; 1 each
// when right) and per axis, the pose NEES under the unweighted estimator's own covariance,
// the corners' centroid against its modelled variance, the corner errors by edge mode,
// and the pose NEES with one term's variance halved (which term the pose's covariance
// rests on). An optional argument names a folder that caches the draws between runs.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <type_traits>

#include <Eigen/Eigenvalues>

#include "covtrack/protocol/camera_opencv.hpp"
#include "lens_edge_bend.hpp"
#include "fiducial_heldout_sets.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;
using test::TagRun;

namespace {

using Draws = std::vector<std::vector<ViewDraw>>;

Draws draws_of(const std::vector<TagRun>& runs, std::uint64_t first_seed) {
  Draws out;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    auto d = draw_view(test::detector_options(runs[i]), runs[i].view, test::kDraws, first_seed + i);
    out.push_back(d ? *d : std::vector<ViewDraw>{});
  }
  return out;
}

// The draws are what takes minutes; a second run with the same cache file reads them
// back (trying model changes). The file holds this build's memory image of each field:
// it is only valid for the binary that wrote it.
template <typename Stream, typename T>
void raw(Stream& s, T& value) {
  static_assert(std::is_trivially_copyable_v<T>);
  if constexpr (std::is_same_v<Stream, std::ifstream>) s.read(reinterpret_cast<char*>(&value), sizeof value);
  else s.write(reinterpret_cast<const char*>(&value), sizeof value);
}
template <typename Stream>
void fields(Stream& s, ViewDraw& d) {
  for (int i = 0; i < 16; ++i) raw(s, d.T_camera_tag_true.matrix().data()[i]);
  bool detected = d.detection.has_value();
  raw(s, detected);
  if (detected) {
    if (!d.detection) d.detection.emplace();
    raw(s, d.detection->id), raw(s, d.detection->hamming), raw(s, d.detection->decision_margin);
    for (auto& p : d.detection->corners_px) raw(s, p.x), raw(s, p.y);
  }
  raw(s, d.inputs);
  for (auto& p : d.truth_px) raw(s, p.x), raw(s, p.y);
}

Draws cached_draws(const std::vector<TagRun>& runs, std::uint64_t first_seed, const std::string& file) {
  if (!file.empty())
    if (std::ifstream in(file, std::ios::binary); in) {
      Draws out(runs.size(), std::vector<ViewDraw>(test::kDraws));
      for (std::size_t v = 0; v < out.size(); ++v)
        for (auto& d : out[v]) {
          fields(in, d);
          if (d.detection) d.lens_bend_px = straight_fit_corner_offsets(runs[v].view.camera, d.detection->corners_px);
        }
      if (in) return out;
    }
  Draws out = draws_of(runs, first_seed);
  if (!file.empty()) {
    std::ofstream f(file, std::ios::binary);
    for (auto& view : out) {
      view.resize(test::kDraws);
      for (auto& d : view) fields(f, d);
    }
  }
  return out;
}

// Each view's mean outward edge errors in the four modes of a square's edges: common
// (the apparent size), aspect (one pair out, the other in) and the two translations
// (one edge of a pair out, the opposite in). Mean squares over views less the means'
// sampling variance, observed next to what the model's edge and line terms give.
void print_view_edge_modes(const char* set, const std::vector<TagRun>& runs, const Draws& draws, const CornerNoiseModel& m) {
  std::map<std::string, std::array<double, 9>> sums;
  for (std::size_t v = 0; v < runs.size(); ++v) {
    std::vector<CornerErrors> errors;
    double edge_var = 0;
    for (const ViewDraw& d : draws[v])
      if (d.detection && std::isfinite(d.inputs.blur_px)) {
        errors.push_back(corner_errors(m, d));
        edge_var += std::pow(m.edge_sigma(d.inputs), 2);
      }
    const double n = static_cast<double>(errors.size());
    if (n < 3) continue;
    edge_var /= n;
    const auto modes = [](const std::array<double, 4>& o) {
      return std::array<double, 4>{(o[0] + o[1] + o[2] + o[3]) / 4, (o[0] + o[2] - o[1] - o[3]) / 4, (o[0] - o[2]) / 2,
                                   (o[1] - o[3]) / 2};
    };
    std::array<double, 4> mean{}, var{};
    std::vector<std::array<double, 4>> each;
    for (const auto& e : errors) each.push_back(modes(e.edge_out_px));
    for (const auto& x : each)
      for (int k = 0; k < 4; ++k) mean[k] += x[k] / n;
    for (const auto& x : each)
      for (int k = 0; k < 4; ++k) var[k] += std::pow(x[k] - mean[k], 2) / (n - 1);
    for (const std::string& label : {std::string("all"), std::string(runs[v].view.tag.T_camera_tag.translation().z() < 1.0 ? "band 0.5-1 m" : "band 1-1.5 m")}) {
      auto& s = sums[label];
      for (int k = 0; k < 4; ++k) s[k] += mean[k] * mean[k] - var[k] / n, s[4 + k] += var[k];
      s[8] += edge_var;
    }
  }
  std::printf("%s: edge modes, mean square per view (px^2): view means (common, aspect, translations along the two\n"
              "  pairs) | draw-to-draw (the same) | the model's edge_sigma^2 (independent edges put a quarter of it in the\n"
              "  aspect and half in each translation)\n", set);
  for (const auto& [label, s] : sums) {
    std::printf("  %-14s", label.c_str());
    for (int k = 0; k < 8; ++k) std::printf(" %.5f", s[k] / runs.size());
    std::printf(" | %.5f\n", s[8] / runs.size());
  }
}

// The corners' centroid (where a tag's centre is seen, what its position across the line of
// sight rests on): its error against the truth over what the model's corner covariance
// gives it (2 when right), and each term's share of the modelled variance.
void print_centroid(const char* set, const std::vector<TagRun>& runs, const Draws& draws, const CornerNoiseModel& m) {
  const char* names[] = {"independent", "line fit", "shift residual", "edge", "scale", "turn"};
  std::array<double, 6> share{};
  double nees = 0;
  int n = 0;
  for (std::size_t v = 0; v < runs.size(); ++v)
    for (const ViewDraw& d : draws[v]) {
      if (!d.detection || !std::isfinite(d.inputs.blur_px)) continue;
      const auto corrected = move_edges_in(d.detection->corners_px, m.edge_shift_px(d.inputs));
      const CornerErrors e = corner_errors(m, d);
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (const auto& p : e.error_px) c += Eigen::Vector2d(p.x, p.y) / 4;
      Eigen::Matrix<double, 2, 8> P;
      for (int k = 0; k < 4; ++k) P.block<2, 2>(0, 2 * k) = Eigen::Matrix2d::Identity() / 4;
      const CornerNoise all = m.noise(d.inputs);
      const Eigen::Matrix2d C = P * corner_covariance(corrected, all) * P.transpose();
      nees += c.dot(C.ldlt().solve(c)), ++n;
      for (int t = 0; t < 6; ++t) {
        CornerNoise one{};
        one.sigma_px = t == 0 ? all.sigma_px : 0;
        one.line_sigma_px = t == 1 ? all.line_sigma_px : 0;
        if (t == 2) one.extra_px = all.extra_px;
        one.edge_sigma_px = t == 3 ? all.edge_sigma_px : 0;
        one.scale_sigma_px = t == 4 ? all.scale_sigma_px : 0;
        one.tilt_sigma_px = t == 5 ? all.tilt_sigma_px : 0;
        share[static_cast<std::size_t>(t)] += (P * corner_covariance(corrected, one) * P.transpose()).trace() / C.trace();
      }
    }
  std::printf("%s: corners' centroid NEES %.2f (2 expected) over %d draws; share of its modelled variance:", set,
              nees / n, n);
  for (int t = 0; t < 6; ++t) std::printf(" %s %.2f", names[t], share[static_cast<std::size_t>(t)] / n);
  std::printf("\n");
}

// The pose is solved without weights (OpenCV's LM on the corners), while its covariance is
// that of the estimator weighted by the corner covariance. The unweighted estimator's own
// covariance is the sandwich (J^T J)^-1 J^T Sigma J (J^T J)^-1: the pose NEES under each.
void print_sandwich(const char* set, const std::vector<TagRun>& runs, const Draws& draws, const CornerNoiseModel& m) {
  std::array<double, 7> weighted{}, sandwich{};
  double total_w = 0, total_s = 0;
  int n = 0;
  for (std::size_t v = 0; v < runs.size(); ++v)
    for (const ViewDraw& d : draws[v]) {
      if (!d.detection) continue;
      auto pose = estimate_tag_pose(runs[v].view.camera, d.detection->corners_px, runs[v].view.tag.size_m,
                                    corner_noise(m, d));
      if (!pose || pose->ambiguous) continue;
      const Vec6 e = boxminus(d.T_camera_tag_true, pose->best.T_camera_tag);
      const CornerJacobian J = corner_jacobian(runs[v].view.camera, pose->best.T_camera_tag, runs[v].view.tag.size_m);
      const Mat6 JtJ_inv = (J.transpose() * J).inverse();
      const Mat6 S = JtJ_inv * J.transpose() * pose->corner_covariance * J * JtJ_inv;
      const Mat6 W = (J.transpose() * pose->corner_covariance.ldlt().solve(J)).inverse();
      total_w += e.dot(W.ldlt().solve(e)), total_s += e.dot(S.ldlt().solve(e)), ++n;
      const Eigen::SelfAdjointEigenSolver<Mat6> ew(W), es(S);
      for (int i = 0; i < 6; ++i) {
        weighted[static_cast<std::size_t>(i)] += std::pow(ew.eigenvectors().col(i).dot(e), 2) / ew.eigenvalues()[i];
        sandwich[static_cast<std::size_t>(i)] += std::pow(es.eigenvectors().col(i).dot(e), 2) / es.eigenvalues()[i];
      }
    }
  std::printf("%s: pose NEES (not ambiguous, %d draws) under the weighted estimator's covariance %.2f, per principal "
              "direction", set, n, total_w / n);
  for (int i = 0; i < 6; ++i) std::printf(" %.2f", weighted[static_cast<std::size_t>(i)] / n);
  std::printf("; under the unweighted one's (sandwich) %.2f,", total_s / n);
  for (int i = 0; i < 6; ++i) std::printf(" %.2f", sandwich[static_cast<std::size_t>(i)] / n);
  std::printf("\n");
}

// The pose's tightest principal direction u rests on one combination of the corners,
// w . dc with w = Sigma_c^-1 J C u (the weighted estimator's). Its observed variance over the
// modelled one, split into the draw-to-draw part (against the independent and line terms)
// and the views' mean (against the systematic terms: edge, scale, turn).
void print_tightest(const char* set, const std::vector<TagRun>& runs, const Draws& draws, const CornerNoiseModel& m) {
  std::map<std::string, std::array<double, 4>> groups;  // draw-to-draw and views' means: observed, modelled
  for (std::size_t v = 0; v < runs.size(); ++v) {
    std::vector<double> values;
    double indep = 0, systematic = 0;
    for (const ViewDraw& d : draws[v]) {
      if (!d.detection) continue;
      const Camera& cam = runs[v].view.camera;
      const double size = runs[v].view.tag.size_m;
      auto pose = estimate_tag_pose(cam, d.detection->corners_px, size, corner_noise(m, d));
      if (!pose || pose->ambiguous) continue;
      const CornerJacobian J = corner_jacobian(cam, pose->best.T_camera_tag, size);
      const Eigen::SelfAdjointEigenSolver<Mat6> eig(pose->covariance);
      const Vec6 u = eig.eigenvectors().col(0);
      const Eigen::Matrix<double, 8, 1> w = pose->corner_covariance.ldlt().solve(J * pose->covariance * u);
      Eigen::Matrix<double, 8, 1> dc;
      const auto X = tag_corner_points(size);
      for (int k = 0; k < 4; ++k) {
        const cv::Point2d truth = pinhole_pixel(cam, d.T_camera_tag_true * X[static_cast<std::size_t>(k)]);
        dc[2 * k] = pose->corners_px[static_cast<std::size_t>(k)].x - truth.x;
        dc[2 * k + 1] = pose->corners_px[static_cast<std::size_t>(k)].y - truth.y;
      }
      values.push_back(w.dot(dc));
      CornerNoise part = m.noise(d.inputs);
      part.scale_sigma_px = part.edge_sigma_px = part.tilt_sigma_px = 0;
      const double wi = w.dot(corner_covariance(pose->corners_px, part) * w);
      indep += wi, systematic += w.dot(pose->corner_covariance * w) - wi;
    }
    const double n = static_cast<double>(values.size());
    if (n < 3) continue;
    double mean = 0, var = 0;
    for (double x : values) mean += x / n;
    for (double x : values) var += (x - mean) * (x - mean) / (n - 1);
    // By what the model cannot see (the camera, the rasteriser, JPEG, the tone curve, ...).
    const auto& f = runs[v].view.formation;
    const std::string rasteriser[] = {"supersampled", "analytic", "jittered"};
    const std::string groups_of_view[] = {
        "all", "camera " + std::to_string(runs[v].view.camera.width_px),
        "rasteriser " + rasteriser[static_cast<int>(f.rasteriser)], std::string("JPEG ") + (f.jpeg_quality ? "yes" : "no"),
        std::string("gamma ") + (f.gamma > 1.7 ? "1.7-2.4" : "1.0-1.7"),
        std::string("defocus ") + (f.defocus_radius_px > 0 ? "yes" : "no"),
        std::string("shot noise ") + (f.full_well_e > 0 ? "yes" : "no")};
    for (const auto& key : groups_of_view) {
      auto& g = groups[key];
      g[0] += var, g[1] += indep / n, g[2] += mean * mean - var / n, g[3] += systematic / n;
    }
  }
  std::printf("%s: the tightest direction's corner combination, observed / modelled: draw to draw, views' means "
              "(modelled share of the views' means)\n", set);
  for (const auto& [key, g] : groups)
    std::printf("  %-22s %5.2f %5.2f (%.2f)\n", key.c_str(), g[0] / g[1], g[2] / g[3], g[3] / (g[3] + g[1]));
}

// The draw-to-draw spread of each view's corner errors (about the view's mean) split into
// the edges' line modes: the four edges' common outward move, each edge's own (the rest
// of the outward moves) and the edges' turns; observed over what the model's independent
// corner covariance puts in the same mode.
void print_draw_modes(const char* set, const std::vector<TagRun>& runs, const Draws& draws, const CornerNoiseModel& m) {
  std::map<std::string, std::array<double, 6>> sums;  // observed and modelled: common, own, turn
  for (std::size_t v = 0; v < runs.size(); ++v) {
    std::vector<const ViewDraw*> used;
    for (const ViewDraw& d : draws[v])
      if (d.detection && std::isfinite(d.inputs.blur_px)) used.push_back(&d);
    const double n = static_cast<double>(used.size());
    if (n < 3) continue;
    std::vector<Eigen::Matrix<double, 8, 1>> modes;
    Eigen::Matrix<double, 8, 1> mean = Eigen::Matrix<double, 8, 1>::Zero();
    Eigen::Matrix<double, 8, 8> modelled = Eigen::Matrix<double, 8, 8>::Zero();
    for (const ViewDraw* d : used) {
      const auto corrected = move_edges_in(d->detection->corners_px, m.edge_shift_px(d->inputs));
      const Eigen::Matrix<double, 8, 8> Minv = edge_line_modes(corrected).inverse();
      const CornerErrors e = corner_errors(m, *d);
      Eigen::Matrix<double, 8, 1> err;
      for (int k = 0; k < 4; ++k) err[2 * k] = e.error_px[k].x, err[2 * k + 1] = e.error_px[k].y;
      modes.push_back(Minv * err), mean += modes.back() / n;
      CornerNoise independent = m.noise(d->inputs);
      independent.scale_sigma_px = independent.edge_sigma_px = independent.tilt_sigma_px = 0;
      modelled += Minv * corner_covariance(corrected, independent) * Minv.transpose() / n;
    }
    Eigen::Matrix<double, 8, 8> observed = Eigen::Matrix<double, 8, 8>::Zero();
    for (const auto& x : modes) observed += (x - mean) * (x - mean).transpose() / (n - 1);
    Eigen::Matrix<double, 8, 8> P = Eigen::Matrix<double, 8, 8>::Zero();  // common, own x4 (rank 3), turns
    P.topLeftCorner<4, 4>().setConstant(0.25);
    const auto share = [](const Eigen::Matrix<double, 8, 8>& C, const Eigen::Matrix<double, 8, 8>& Q) {
      return (Q * C * Q.transpose()).trace();
    };
    Eigen::Matrix<double, 8, 8> own = -P;
    own.topLeftCorner<4, 4>() += Eigen::Matrix4d::Identity();
    Eigen::Matrix<double, 8, 8> turns = Eigen::Matrix<double, 8, 8>::Zero();
    turns.bottomRightCorner<4, 4>().setIdentity();
    for (const std::string& label :
         {std::string("all"), std::string(runs[v].view.tag.T_camera_tag.translation().z() < 1.0 ? "band 0.5-1 m" : "band 1-1.5 m")}) {
      auto& s = sums[label];
      s[0] += share(observed, P), s[1] += share(modelled, P);
      s[2] += share(observed, own), s[3] += share(modelled, own);
      s[4] += share(observed, turns), s[5] += share(modelled, turns);
    }
  }
  print_view_edge_modes(set, runs, draws, m);
  std::printf("%s: draw-to-draw spread by edge mode, observed / modelled independent variance\n", set);
  std::printf("  %-14s %7s %7s %7s   (modelled px^2 per view: common, own, turn)\n", "group", "common", "own", "turn");
  for (const auto& [label, s] : sums)
    std::printf("  %-14s %7.2f %7.2f %7.2f   %.5f %.5f %.5f\n", label.c_str(), s[0] / s[1], s[2] / s[3], s[4] / s[5],
                s[1] / runs.size(), s[3] / runs.size(), s[5] / runs.size());
}

bool near_band(const TagRun& r) { return r.view.tag.T_camera_tag.translation().z() < 1.0; }

struct Ratio {
  double observed = 0, modelled = 0;
  double value() const { return modelled > 0 ? observed / modelled : 0; }
  Ratio& operator+=(const Ratio& r) {
    observed += r.observed, modelled += r.modelled;
    return *this;
  }
};
struct Group {
  Ratio indep, scale, edge, turn;
  double nees_sum = 0;
  int nees_n = 0, views = 0;
};

// One view's contributions (the same split as the calibration's stages 2 and 3).
void add_view(Group& g, const TagRun& run, const std::vector<ViewDraw>& draws, const CornerNoiseModel& m) {
  std::vector<CornerErrors> errors;
  std::vector<const ViewDraw*> used;
  for (const ViewDraw& d : draws)
    if (d.detection && std::isfinite(d.inputs.blur_px)) errors.push_back(corner_errors(m, d)), used.push_back(&d);
  const double n = static_cast<double>(errors.size());
  if (n < 3) return;
  std::array<cv::Point2d, 4> mean{};
  for (const auto& e : errors)
    for (std::size_t k = 0; k < 4; ++k) mean[k] += e.error_px[k] / n;
  for (std::size_t j = 0; j < errors.size(); ++j) {
    const CornerNoise noise = m.noise(used[j]->inputs);
    for (std::size_t k = 0; k < 4; ++k) {
      const cv::Point2d e = errors[j].error_px[k] - mean[k];
      g.indep.observed += e.dot(e) * n / (n - 1) / 2;
      g.indep.modelled += noise.sigma_px * noise.sigma_px + noise.line_sigma_px * noise.line_sigma_px +
                          noise.extra_px[k] * noise.extra_px[k];
    }
  }
  std::array<double, 4> out{}, out_var{}, turn{}, turn_var{};
  for (const auto& e : errors)
    for (std::size_t k = 0; k < 4; ++k) out[k] += e.edge_out_px[k] / n, turn[k] += e.edge_turn_px[k] / n;
  for (const auto& e : errors)
    for (std::size_t k = 0; k < 4; ++k) {
      out_var[k] += std::pow(e.edge_out_px[k] - out[k], 2) / (n - 1);
      turn_var[k] += std::pow(e.edge_turn_px[k] - turn[k], 2) / (n - 1);
    }
  const double common = (out[0] + out[1] + out[2] + out[3]) / 4;
  const double mean_var = (out_var[0] + out_var[1] + out_var[2] + out_var[3]) / 4;
  double rest = 0, turn_sq = 0, turn_mean_var = 0;
  for (std::size_t k = 0; k < 4; ++k)
    rest += std::pow(out[k] - common, 2) / 4, turn_sq += turn[k] * turn[k] / 4, turn_mean_var += turn_var[k] / 4;
  const CornerNoise noise = m.noise(used[0]->inputs);
  g.scale.observed += common * common - mean_var / (4 * n);
  g.scale.modelled += noise.scale_sigma_px * noise.scale_sigma_px;
  // The phase-locked terms are each edge's own: their mean over the edges joins the
  // edge's and the turn's modelled variance.
  double locked_edge = 0, locked_tilt = 0;
  for (std::size_t k = 0; k < 4; ++k)
    locked_edge += std::pow(noise.locked_edge_px[k], 2) / 4, locked_tilt += std::pow(noise.locked_tilt_px[k], 2) / 4;
  g.edge.observed += (rest - 0.75 * mean_var / n) * 4 / 3;
  g.edge.modelled += noise.edge_sigma_px * noise.edge_sigma_px + locked_edge;
  g.turn.observed += turn_sq - turn_mean_var / n;
  g.turn.modelled += noise.tilt_sigma_px * noise.tilt_sigma_px + locked_tilt;
  int posed = 0;
  const double nees = mean_pose_nees(run.view, draws, m, &posed);
  g.nees_sum += nees * posed, g.nees_n += posed, ++g.views;
}

void print_terms(const char* set, const std::vector<TagRun>& runs, const Draws& draws, const CornerNoiseModel& m) {
  constexpr double kEdges[] = {0, 50, 80, 120, 180, 1e9};
  std::map<std::string, Group> groups;
  for (std::size_t v = 0; v < runs.size(); ++v) {
    double length = 0;
    int n = 0;
    for (const ViewDraw& d : draws[v])
      if (d.detection) length += d.inputs.edge_length_px, ++n;
    if (!n) continue;
    length /= n;
    std::size_t b = 0;
    while (length >= kEdges[b + 1]) ++b;
    char label[32];
    std::snprintf(label, sizeof label, "edge %3.0f-%3.0f px", kEdges[b], std::min(kEdges[b + 1], 999.0));
    add_view(groups[label], runs[v], draws[v], m);
    add_view(groups[near_band(runs[v]) ? "band 0.5-1 m" : "band 1-1.5 m"], runs[v], draws[v], m);
    const char* rasteriser[] = {"supersampled", "analytic", "jittered"};
    add_view(groups[rasteriser[static_cast<int>(runs[v].view.formation.rasteriser)]], runs[v], draws[v], m);
    add_view(groups[runs[v].view.formation.gamma > 1.7 ? "gamma 1.7-2.4" : "gamma 1.0-1.7"], runs[v], draws[v], m);
    add_view(groups["camera " + std::to_string(runs[v].view.camera.width_px)], runs[v], draws[v], m);
  }
  std::printf("%s: observed / modelled variance per term\n", set);
  std::printf("  %-16s %5s %6s %6s %6s %6s %6s\n", "group", "views", "NEES", "indep", "scale", "edge", "turn");
  for (const auto& [label, g] : groups)
    std::printf("  %-16s %5d %6.2f %6.2f %6.2f %6.2f %6.2f\n", label.c_str(), g.views,
                g.nees_n ? g.nees_sum / g.nees_n : 0, g.indep.value(), g.scale.value(), g.edge.value(),
                g.turn.value());
}

// Per draw, the corner errors in the edge modes of the draw's own quad (edge_line_modes:
// 4 outward offsets, 4 turns), split into the tag's apparent scale (the offsets' mean),
// each edge's own placement (the rest of the offsets) and the turns; each part's mean
// square against the same part of the model's full corner covariance (phase-locked terms
// included), so that a term's excess shows apart from the others. By the tag's mean edge
// length, camera and whether any edge is locked (lock over 0.5).
void print_mode_terms(const char* set, const std::vector<TagRun>& runs, const Draws& draws, const CornerNoiseModel& m) {
  struct Parts {
    Ratio scale, placement, turn;
    int draws = 0;
  };
  std::map<std::string, Parts> groups;
  const Eigen::Matrix4d rest = Eigen::Matrix4d::Identity() - Eigen::Matrix4d::Constant(0.25);
  for (std::size_t v = 0; v < runs.size(); ++v)
    for (const ViewDraw& d : draws[v]) {
      if (!d.detection || !std::isfinite(d.inputs.blur_px)) continue;
      const CornerErrors e = corner_errors(m, d);
      std::array<cv::Point2d, 4> corners;
      Eigen::Matrix<double, 8, 1> error;
      for (int k = 0; k < 4; ++k) {
        corners[k] = d.truth_px[k] + e.error_px[k];
        error(2 * k) = e.error_px[k].x, error(2 * k + 1) = e.error_px[k].y;
      }
      const Eigen::Matrix<double, 8, 8> to_modes = edge_line_modes(corners).inverse();
      const Eigen::Matrix<double, 8, 1> q = to_modes * error;
      const Eigen::Matrix<double, 8, 8> C = to_modes * corner_covariance(corners, corner_noise(m, d)) * to_modes.transpose();
      const Eigen::Matrix4d offsets = C.topLeftCorner<4, 4>();
      const double length = d.inputs.edge_length_px;
      const bool locked = *std::max_element(d.inputs.phase_lock.begin(), d.inputs.phase_lock.end()) > 0.5;
      const std::string keys[] = {length < 60 ? "edge <60 px" : length < 150 ? "edge 60-150 px" : "edge 150+ px",
                                  "camera " + std::to_string(runs[v].view.camera.width_px),
                                  locked ? "an edge locked" : "none locked", "all"};
      const double s = q.head<4>().mean();
      const Parts draw{{s * s, offsets.sum() / 16},
                       {(rest * q.head<4>()).squaredNorm(), (rest * offsets * rest).trace()},
                       {q.tail<4>().squaredNorm(), C.bottomRightCorner<4, 4>().trace()},
                       1};
      for (const std::string& key : keys) {
        Parts& p = groups[key];
        p.scale += draw.scale, p.placement += draw.placement, p.turn += draw.turn;
        ++p.draws;
      }
    }
  std::printf("%s: per draw, observed / modelled mean square in the quad's edge modes\n", set);
  std::printf("  %-16s %6s %7s %9s %6s\n", "group", "draws", "scale", "placement", "turn");
  for (const auto& [label, p] : groups)
    std::printf("  %-16s %6d %7.2f %9.2f %6.2f\n", label.c_str(), p.draws, p.scale.value(), p.placement.value(),
                p.turn.value());
}

void print_directions(const char* set, const std::vector<TagRun>& runs, const Draws& draws, const CornerNoiseModel& m) {
  std::map<std::string, std::array<double, 7>> sums, axes;  // six directions and the count
  for (std::size_t v = 0; v < runs.size(); ++v)
    for (const ViewDraw& d : draws[v]) {
      if (!d.detection) continue;
      auto pose = estimate_tag_pose(runs[v].view.camera, d.detection->corners_px, runs[v].view.tag.size_m,
                                    corner_noise(m, d));
      if (!pose) continue;
      const Vec6 e = boxminus(d.T_camera_tag_true, pose->best.T_camera_tag);
      const Eigen::SelfAdjointEigenSolver<Mat6> eig(pose->covariance);
      auto& s = sums[near_band(runs[v]) ? "band 0.5-1 m" : "band 1-1.5 m"];
      for (int i = 0; i < 6; ++i) s[i] += std::pow(eig.eigenvectors().col(i).dot(e), 2) / eig.eigenvalues()[i];
      s[6] += 1;
      // The tag centre's position in the camera's axes (x, y across the line of sight, z
      // along it) and the turns about the tag's own axes (x, y in its plane, z its normal).
      Mat6 to_camera = Mat6::Identity();
      to_camera.topLeftCorner<3, 3>() = pose->best.T_camera_tag.rotation();
      const Vec6 ec = to_camera * e;
      const Mat6 cc = to_camera * pose->covariance * to_camera.transpose();
      auto& a = axes[near_band(runs[v]) ? "band 0.5-1 m" : "band 1-1.5 m"];
      for (int i = 0; i < 6; ++i) a[i] += ec[i] * ec[i] / cc(i, i);
      a[6] += 1;
    }
  std::printf("%s: pose NEES per principal direction, tightest first\n", set);
  for (const auto& [label, s] : sums) {
    std::printf("  %-16s", label.c_str());
    for (int i = 0; i < 6; ++i) std::printf(" %5.2f", s[i] / s[6]);
    std::printf("\n");
  }
  std::printf("%s: NEES per axis: centre x, y, z in the camera's axes; turns about the tag's x, y, z\n", set);
  for (const auto& [label, s] : axes) {
    std::printf("  %-16s", label.c_str());
    for (int i = 0; i < 6; ++i) std::printf(" %5.2f", s[i] / s[6]);
    std::printf("\n");
  }
}

void print_halved(const char* set, const std::vector<TagRun>& runs, const Draws& draws, const CornerNoiseModel& m) {
  const double f = std::sqrt(0.5);
  std::vector<std::pair<const char*, CornerNoiseModel>> models{{"none", m}};
  const auto halved = [&](const char* name, std::initializer_list<double CornerNoiseModel::*> fields) {
    CornerNoiseModel x = m;
    for (auto field : fields) x.*field *= f;
    models.emplace_back(name, x);
  };
  halved("floor", {&CornerNoiseModel::floor_px});
  halved("sample floor", {&CornerNoiseModel::sample_floor_px});
  halved("gain", {&CornerNoiseModel::gain_px});
  halved("aligned", {&CornerNoiseModel::aligned_px});
  halved("shift sigma", {&CornerNoiseModel::shift_sigma_px});
  halved("scale", {&CornerNoiseModel::scale_sigma_px, &CornerNoiseModel::scale_per_blur});
  halved("edge", {&CornerNoiseModel::edge_sigma_px, &CornerNoiseModel::edge_per_blur});
  halved("turn", {&CornerNoiseModel::tilt_sigma_px, &CornerNoiseModel::tilt_per_blur});
  std::printf("%s: pose NEES (all, 0.5-1 m, 1-1.5 m) with one term's variance halved\n", set);
  for (const auto& [name, x] : models) {
    std::array<double, 3> sum{};
    std::array<int, 3> count{};
    for (std::size_t v = 0; v < runs.size(); ++v) {
      int posed = 0;
      const double nees = mean_pose_nees(runs[v].view, draws[v], x, &posed);
      for (std::size_t g : {std::size_t{0}, std::size_t{near_band(runs[v]) ? 1u : 2u}})
        sum[g] += nees * posed, count[g] += posed;
    }
    std::printf("  %-14s %6.2f %6.2f %6.2f\n", name, sum[0] / count[0], sum[1] / count[1], sum[2] / count[2]);
  }
}

}  // namespace

int main(int argc, char** argv) {
  // --locked: only the phase-locked views (fiducial_heldout_nees_test's seeds), under the
  // shipped model, by mode (seconds, not minutes).
  if (argc > 1 && std::string(argv[1]) == "--locked") {
    const CornerNoiseModel shipped;
    const auto calibration = test::locked_edge_calibration_set();
    const auto validation = test::locked_edge_validation_set();
    const Draws calibration_draws = draws_of(calibration, 7000), validation_draws = draws_of(validation, 8000);
    print_mode_terms("locked calibration", calibration, calibration_draws, shipped);
    print_mode_terms("locked validation", validation, validation_draws, shipped);
    print_terms("locked calibration", calibration, calibration_draws, shipped);
    print_terms("locked validation", validation, validation_draws, shipped);
    return 0;
  }
  // Optional: a cache folder for the draws (see cached_draws).
  const std::string cache = argc > 1 ? argv[1] : "";
  const auto calibration = test::calibration_set();
  const auto validation = test::validation_set();
  const Draws calibration_draws = cached_draws(calibration, 1, cache.empty() ? "" : cache + "/calibration.bin");  // the test's seeds
  std::vector<CalibrationView> views;
  for (const auto& r : calibration) views.push_back(r.view);
  const CornerNoiseModel model = fit_corner_noise(views, calibration_draws);
  std::printf("calibrated: %s\n", describe(model).c_str());
  const Draws validation_draws = cached_draws(validation, 5000, cache.empty() ? "" : cache + "/validation.bin");
  struct Set {
    const char* name;
    const std::vector<TagRun>& runs;
    const Draws& draws;
  };
  const Set sets[] = {{"calibration", calibration, calibration_draws}, {"validation", validation, validation_draws}};
  for (auto print : {print_tightest, print_sandwich, print_centroid, print_draw_modes, print_terms, print_directions, print_halved})
    for (const Set& set : sets) print(set.name, set.runs, set.draws, model);
}
