// The fiducial tracker's covariance holds on images made differently from those its
// corner model was calibrated on. Both sets draw random cameras from one population
// (tone curve gamma 1-2.4, Gaussian blur with or without defocus, JPEG or none,
// vignetting, shot and read noise, print contrast). Calibration: the supersampling and the
// exact-area rasterisers in turn, a 640x480 camera and a 1280x720 one with known
// distortion, four families (both border polarities). Validation, held out in renderer,
// resolution, family and lens: a third rasteriser (random points per pixel, with a fill
// factor), an 800x600 camera and a 1920x1080 one whose distortion the driver knows only
// approximately, four other families. Checked: every
// condition (family x resolution x distance band) within 2x (mean NEES in [3, 12]), so is
// every band of edge length with 10 views or more, the pooled NEES (see the bound below),
// and that the shipped defaults are this calibration. The phase-locked edges' terms are
// fitted and judged on sets of their own (the second test).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>

#include "covtrack/emulators/fiducial/noise_calibration.hpp"
#include "fiducial_heldout_sets.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;
using test::TagRun;
using test::kDraws;
using test::calibration_set;
using test::validation_set;

namespace {

std::vector<ViewDraw> draws_of(const TagRun& r, std::uint64_t seed) {
  auto draws = draw_view(detector_options(r), r.view, kDraws, seed);
  EXPECT_TRUE(draws.has_value()) << draws.error().message;
  return draws ? *draws : std::vector<ViewDraw>{};
}

// One line per view: how it was made, how far its corners were off, its mean pose NEES.
// Returns each view's mean pose NEES and how many draws it is over.
std::vector<std::pair<double, int>> print_views(const std::vector<TagRun>& runs,
                                                const std::vector<std::vector<ViewDraw>>& draws,
                                                const CornerNoiseModel& model) {
  std::vector<std::pair<double, int>> nees;
  std::printf("%4s %-17s %9s %5s %5s %4s %4s %6s %7s %7s %7s\n", "view", "family", "camera", "gamma",
              "blur", "defo", "jpeg", "edge", "rmsCorn", "common", "NEES");
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const auto& f = runs[i].view.formation;
    double sq = 0, common = 0, edge = 0;
    int n = 0;
    for (const ViewDraw& d : draws[i]) {
      if (!d.detection) continue;
      const CornerErrors e = corner_errors(model, d);
      for (const auto& p : e.error_px) sq += p.dot(p) / 8;
      for (double out : e.edge_out_px) common += out / 4;
      edge += d.inputs.edge_length_px, ++n;
    }
    auto& [mean_nees, posed] = nees.emplace_back();
    mean_nees = mean_pose_nees(runs[i].view, draws[i], model, &posed);
    std::printf("%4zu %-17s %4dx%-4d %5.1f %5.2f %4.1f %4d %6.1f %7.3f %7.3f %7.2f\n", i,
                runs[i].family.c_str(), runs[i].view.camera.width_px, runs[i].view.camera.height_px,
                f.gamma, f.gauss_blur_px, f.defocus_radius_px, f.jpeg_quality, n ? edge / n : 0,
                n ? std::sqrt(sq / n) : 0, n ? common / n : 0, mean_nees);
  }
  return nees;
}

}  // namespace

TEST(FiducialHeldOutNees, CovarianceHoldsOnImagesMadeDifferently) {
  // Calibrate: the corner model's coefficients from the calibration runs' draws.
  const auto calibration = calibration_set();
  std::vector<CalibrationView> views;
  std::vector<std::vector<ViewDraw>> draws;
  int detected = 0;
  for (std::size_t i = 0; i < calibration.size(); ++i) {
    views.push_back(calibration[i].view);
    draws.push_back(draws_of(calibration[i], 1 + i));
    for (const auto& d : draws.back()) detected += d.detection.has_value();
  }
  EXPECT_GE(detected, static_cast<int>(calibration.size()) * kDraws * 9 / 10);
  const CornerNoiseModel model = fit_corner_noise(views, draws);
  print_views(calibration, draws, model);
  std::printf("calibrated: %s\n", describe(model).c_str());
  // The shipped defaults must be this calibration's
  // result (a change that moves it must update them: corner_noise.hpp, config/schema.md).
  const CornerNoiseModel shipped;
  const auto near = [](double fitted, double default_value) {
    return std::abs(fitted - default_value) <= 0.001 + 0.05 * std::abs(default_value);
  };
  EXPECT_TRUE(near(model.gain_px, shipped.gain_px) && near(model.floor_px, shipped.floor_px) &&
              near(model.sample_floor_px, shipped.sample_floor_px) &&
              near(model.aligned_px, shipped.aligned_px) && near(model.shift_px, shipped.shift_px) &&
              near(model.shift_sigma_px, shipped.shift_sigma_px) &&
              near(model.scale_bias_per_blur, shipped.scale_bias_per_blur) &&
              near(model.scale_sigma_px, shipped.scale_sigma_px) &&
              near(model.scale_per_blur, shipped.scale_per_blur) &&
              near(model.edge_sigma_px, shipped.edge_sigma_px) &&
              near(model.edge_per_blur, shipped.edge_per_blur) &&
              near(model.tilt_sigma_px, shipped.tilt_sigma_px) && near(model.tilt_per_blur, shipped.tilt_per_blur))
      << "the shipped corner model defaults differ from this calibration";

  // Validate on the held-out runs.
  const auto validation = validation_set();
  std::map<std::string, std::pair<double, int>> by_condition, by_band;
  // By the view's mean edge length: under 60 px, 60-90, 90-150, 150 and over.
  struct SizeBand {
    const char* name;
    double sum = 0;
    int draws = 0, views = 0;
  };
  std::array<SizeBand, 4> by_size{{{"under 60 px"}, {"60-90 px"}, {"90-150 px"}, {"150 px and over"}}};
  double pooled_sum = 0;
  int pooled_n = 0;
  std::vector<std::vector<ViewDraw>> validation_draws;
  for (std::size_t i = 0; i < validation.size(); ++i) validation_draws.push_back(draws_of(validation[i], 5000 + i));
  const auto view_nees = print_views(validation, validation_draws, model);
  for (std::size_t i = 0; i < validation.size(); ++i) {
    const TagRun& r = validation[i];
    const auto [mean, n] = view_nees[i];
    by_condition[r.condition].first += mean * n;
    by_condition[r.condition].second += n;
    auto& band = by_band[r.condition.substr(r.condition.rfind(' ', r.condition.size() - 3) + 1)];
    band.first += mean * n, band.second += n;
    pooled_sum += mean * n, pooled_n += n;
    double edge = 0;
    int seen = 0;
    for (const ViewDraw& d : validation_draws[i])
      if (d.detection) edge += d.inputs.edge_length_px, ++seen;
    if (seen == 0) continue;  // no size to file it under (and no pose to judge)
    edge /= seen;
    SizeBand& size = by_size[edge < 60 ? 0 : edge < 90 ? 1 : edge < 150 ? 2 : 3];
    size.sum += mean * n, size.draws += n, ++size.views;
  }
  std::printf("%-34s %6s %4s\n", "condition", "NEES", "n");
  for (const auto& [condition, sum_n] : by_condition) {
    const double mean = sum_n.second ? sum_n.first / sum_n.second : 0;
    std::printf("%-34s %6.2f %4d\n", condition.c_str(), mean, sum_n.second);
    EXPECT_GE(sum_n.second, 8 * kDraws * 8 / 10) << condition << ": too few detections";
    EXPECT_LE(mean, 12.0) << condition << " is over 2x over-confident";
    EXPECT_GE(mean, 3.0) << condition << " is over 2x under-confident";
  }
  // Near tags are large in pixels, far ones small: a term that does not follow the tag's
  // size in pixels shows as one band more conservative than the other (before the
  // per-sample floor, near 4.38 against far 5.35). It is a coarse check: on other validation
  // sets of this design the same model reads 1.01-1.30x (fiducial_heldout_replication).
  const auto band_mean = [&](const std::string& band) {
    const auto& [sum, n] = by_band[band];
    return n ? sum / n : 0.0;
  };
  const double near_band = band_mean("0.5-1 m"), far_band = band_mean("1-1.5 m");
  std::printf("distance bands: 0.5-1 m NEES %.2f, 1-1.5 m NEES %.2f\n", near_band, far_band);
  EXPECT_LT(std::max(near_band, far_band), 1.2 * std::min(near_band, far_band))
      << "the near and far bands' NEES differ by more than 1.2x";
  // Within 2x as the conditions are, where a band has enough views to say (few views are of
  // tags under 60 px: devices/fiducial/README.md, "Limits").
  for (const SizeBand& b : by_size) {
    std::printf("edges %s: NEES %.2f over %d draws of %d views\n", b.name, b.draws ? b.sum / b.draws : 0.0,
                b.draws, b.views);
    if (b.views < 10) continue;
    EXPECT_LE(b.sum / b.draws, 12.0) << "edges " << b.name << ": over 2x over-confident";
    EXPECT_GE(b.sum / b.draws, 3.0) << "edges " << b.name << ": over 2x under-confident";
  }
  const double pooled = pooled_sum / pooled_n;
  const double half_width = 2.576 * std::sqrt(12.0 / pooled_n);
  std::printf("pooled mean NEES %.3f over %d draws; chi2(6) 99%% bounds for independent draws [%.3f, %.3f]\n",
              pooled, pooled_n, 6 - half_width, 6 + half_width);
  // Not the chi-square bounds above: a view's systematic corner errors are shared by its
  // draws, so the pool holds only as many draws of them as there are views. The pooled
  // mean measured here (5.47) is 1.10x under-confident, outside those bounds; this asserts
  // the pool within 1.2x either way (1.3x before the noise was measured through JPEG), and
  // every condition within 2x above (devices/fiducial/README.md, "Limits").
  EXPECT_GT(pooled, 6 / 1.2);
  EXPECT_LT(pooled, 6 * 1.2);
  // And 6 within the pool's 99% interval judged with the views as the independent draws:
  // the spread of the views' own means, each weighted by its draws (the pool's standard
  // error for clustered samples). Over eight validation sets of this design the pools
  // spread by 0.26, as this error says (fiducial_heldout_replication; the README's Limits).
  int posed_views = 0;
  const double clustered_se = test::clustered_standard_error(view_nees, &posed_views);
  std::printf("with the %d views as the independent draws: standard error %.3f, 99%% interval for the pool [%.3f, %.3f]\n",
              posed_views, clustered_se, 6 - 2.576 * clustered_se, 6 + 2.576 * clustered_se);
  EXPECT_LE(std::abs(pooled - 6), 2.576 * clustered_se)
      << "the pooled NEES is off 6 by more than the views' own spread allows";
}

// Edges along a pixel row or column (phase-locked: corner_noise.hpp) are rare in a random
// set, so their terms are fitted on views made to have them, and judged on views made
// differently (rasteriser, resolution, family, seed; edges up to twice as far off the
// grid). Without the terms these views read a NEES of about 4x.
TEST(FiducialHeldOutNees, PhaseLockedEdgesAreCoveredOnViewsMadeDifferently) {
  const auto draw_all = [](const std::vector<TagRun>& runs, std::uint64_t seed) {
    std::vector<std::vector<ViewDraw>> draws;
    for (std::size_t i = 0; i < runs.size(); ++i) draws.push_back(draws_of(runs[i], seed + i));
    return draws;
  };
  const auto calibration = test::locked_edge_calibration_set();
  CornerNoiseModel model;
  fit_locked_edges(model, draw_all(calibration, 7000));
  std::printf("locked edges calibrated: %s\n", describe(model).c_str());
  const CornerNoiseModel shipped;
  EXPECT_NEAR(model.locked_edge_px, shipped.locked_edge_px, 0.001 + 0.05 * shipped.locked_edge_px)
      << "the shipped default differs from this calibration";
  EXPECT_NEAR(model.locked_tilt_px, shipped.locked_tilt_px, 0.001 + 0.05 * shipped.locked_tilt_px)
      << "the shipped default differs from this calibration";

  const auto validation = test::locked_edge_validation_set();
  const auto draws = draw_all(validation, 8000);
  CornerNoiseModel without = shipped;
  without.locked_edge_px = without.locked_tilt_px = 0;
  std::vector<std::pair<double, int>> view_nees;
  double sum = 0, sum_without = 0, locked = 0;
  int n = 0, n_without = 0, edges = 0;
  for (std::size_t i = 0; i < validation.size(); ++i) {
    auto& [mean, count] = view_nees.emplace_back();
    mean = mean_pose_nees(validation[i].view, draws[i], shipped, &count);
    int count_without = 0;
    const double mean_without = mean_pose_nees(validation[i].view, draws[i], without, &count_without);
    sum += mean * count, n += count, sum_without += mean_without * count_without, n_without += count_without;
    for (const ViewDraw& d : draws[i])
      if (d.detection)
        for (double lock : d.inputs.phase_lock) locked += lock > 0.5, ++edges;
  }
  ASSERT_GE(n, static_cast<int>(validation.size()) * kDraws * 8 / 10);
  const double pooled = sum / n, clustered_se = test::clustered_standard_error(view_nees);
  std::printf("held-out locked views: NEES %.2f over %d draws (%.2f without the locked terms); %.1f%% of "
              "edges locked over 0.5; 99%% interval with the views as the draws [%.2f, %.2f]\n",
              pooled, n, sum_without / n_without, 100 * locked / edges, 6 - 2.576 * clustered_se,
              6 + 2.576 * clustered_se);
  // The set does have locked edges (else it would judge nothing).
  EXPECT_GE(locked / edges, 0.15);
  // Within 2x, as every condition of the main held-out set. Not within the views' 99%
  // interval: measured 8.76, 1.46x over-confident, most of it on the 1920x1080 camera
  // (10.8; 800x600: 6.8), in sensors whose light-sensitive part is under 85% of the pixel
  // (10.7 there, 6.5 above) and on long edges (devices/fiducial/README.md, "Limits").
  EXPECT_GT(pooled, 3);
  EXPECT_LT(pooled, 12) << "phase-locked edges: over 2x over-confident";
}
