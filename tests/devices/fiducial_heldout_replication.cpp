// Run by hand (about a minute per set): build/tests/devices/fiducial_heldout_replication
//     [DRAWS_PER_VIEW [VIEWS_PER_CONDITION [SEED ...]]]   (defaults: 4 8 23 31 37 41 43 47 53 59)
// How far the held-out test's pooled NEES moves from one validation set to another: sets of
// the same design (validation_set: rasteriser, cameras, families, distance bands) drawn
// from other seeds, judged by the shipped corner model (fiducial_heldout_nees_test asserts
// that it is the calibration's fit). Seed 23's draws are the test's own. Per set: the
// pooled NEES with chi-square(6)'s 99% bounds for that many independent draws, the
// standard error from the spread of the views' means (a view's draws share its systematic
// errors), and the pool by camera and by distance band. Then over the sets: the mean of
// the pools, their spread from set to set against those standard errors, and the share of
// single draws beyond chi-square(6)'s 99% quantile.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "covtrack/emulators/fiducial/noise_calibration.hpp"
#include "fiducial_heldout_sets.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;

namespace {

constexpr double kChi2_6_Quantile99 = 16.812;

struct Sums {
  double sum = 0;
  int n = 0;
  void add(double value, int count) { sum += value * count, n += count; }
  double mean() const { return n ? sum / n : 0.0; }
};

struct SetResult {
  double pooled = 0, views_se = 0;
  int draws = 0, beyond_quantile = 0;
};

SetResult judge_set(std::uint64_t seed, int draws_per_view, int views_per_condition) {
  const auto runs = test::validation_set(seed, views_per_condition);
  const CornerNoiseModel model;
  // Each draw's NEES; the views side by side on two threads, each keeping its own detectors.
  std::vector<std::vector<double>> nees(runs.size());
  {
    std::vector<std::jthread> workers;
    for (std::size_t t = 0; t < 2; ++t)
      workers.emplace_back([&, t] {
        for (std::size_t i = t; i < runs.size(); i += 2) {
          const std::uint64_t first = (seed == 23 ? 5000 : seed * 10000) + i;
          const auto draws = draw_view(test::detector_options(runs[i]), runs[i].view, draws_per_view, first, 1);
          if (!draws) continue;
          for (const ViewDraw& d : *draws) {
            int posed = 0;
            const double value = mean_pose_nees(runs[i].view, {d}, model, &posed);
            if (posed) nees[i].push_back(value);
          }
        }
      });
  }
  Sums pool;
  std::map<std::string, Sums> by_camera, by_band;
  std::vector<std::pair<double, int>> views;  // mean, draws
  SetResult r;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (nees[i].empty()) continue;
    Sums view;
    for (double value : nees[i]) view.add(value, 1), r.beyond_quantile += value > kChi2_6_Quantile99;
    // "family camera band", the band being "0.5-1 m" or "1-1.5 m".
    const std::string& condition = runs[i].condition;
    const std::size_t family_end = condition.find(' '), band_start = condition.rfind(' ', condition.size() - 3) + 1;
    pool.add(view.mean(), view.n);
    by_camera[condition.substr(family_end + 1, band_start - family_end - 2)].add(view.mean(), view.n);
    by_band[condition.substr(band_start)].add(view.mean(), view.n);
    views.emplace_back(view.mean(), view.n);
  }
  r.pooled = pool.mean(), r.draws = pool.n;
  r.views_se = test::clustered_standard_error(views);
  const double half = 2.576 * std::sqrt(12.0 / pool.n);
  std::printf("seed %3llu: pooled %.3f over %d draws of %zu views; independent-draw 99%% bounds [%.3f, %.3f]%s; "
              "views' standard error %.3f;",
              static_cast<unsigned long long>(seed), r.pooled, pool.n, views.size(), 6 - half, 6 + half,
              std::abs(r.pooled - 6) <= half ? "" : " (outside)", r.views_se);
  for (const auto& [name, s] : by_camera) std::printf(" %s %.2f", name.c_str(), s.mean());
  for (const auto& [name, s] : by_band) std::printf(", %s %.2f", name.c_str(), s.mean());
  std::printf("\n");
  std::fflush(stdout);  // a set takes a minute: show each as it ends
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const int draws_per_view = argc > 1 ? std::atoi(argv[1]) : test::kDraws;
  const int views_per_condition = argc > 2 ? std::atoi(argv[2]) : 8;
  std::vector<std::uint64_t> seeds;
  for (int a = 3; a < argc; ++a) seeds.push_back(std::strtoull(argv[a], nullptr, 10));
  if (seeds.empty()) seeds = {23, 31, 37, 41, 43, 47, 53, 59};
  if (draws_per_view < 1 || views_per_condition < 1) {
    std::fprintf(stderr, "usage: %s [DRAWS_PER_VIEW >= 1 [VIEWS_PER_CONDITION >= 1 [SEED ...]]]\n", argv[0]);
    return 2;
  }
  std::vector<SetResult> sets;
  for (std::uint64_t seed : seeds) sets.push_back(judge_set(seed, draws_per_view, views_per_condition));
  double sum = 0, squares = 0, se = 0;
  int draws = 0, beyond = 0;
  for (const SetResult& s : sets) sum += s.pooled, se += s.views_se, draws += s.draws, beyond += s.beyond_quantile;
  const double mean = sum / sets.size();
  for (const SetResult& s : sets) squares += (s.pooled - mean) * (s.pooled - mean);
  std::printf("over %zu sets: mean of the pools %.3f; their spread from set to set %.3f (the views' standard "
              "error, averaged: %.3f; chi-square(6)'s for independent draws: %.3f); draws beyond the 99%% "
              "quantile %.1f%% of %d\n",
              sets.size(), mean, sets.size() > 1 ? std::sqrt(squares / (sets.size() - 1.0)) : 0.0, se / sets.size(),
              std::sqrt(12.0 / (draws / static_cast<double>(sets.size()))), 100.0 * beyond / draws, draws);
}
