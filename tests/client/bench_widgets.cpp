// Widget cost per frame against the regions they use: 100 objects, each region computed
// (UT, the default) vs label placement for all of them vs selection (likelihoods by area
// and by distance, direct selection, indirect targets). Single thread.
// Run: taskset -c 0 build/tests/client/bench_widgets ; ratios = widget time / regions time.
#include <random>

#include <benchmark/benchmark.h>

#include "covtrack/client/label_placer.hpp"
#include "covtrack/client/selection.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

constexpr int kObjects = 100;

struct Frame {
  Camera camera;
  std::vector<UncertainPose> poses;
  std::vector<std::vector<Vec3>> vertices;
  std::vector<ObjectRegions> regions;  // computed once, for the widget benchmarks
};

const Frame& frame() {
  static const Frame f = [] {
    Frame f;
    f.camera.fx = 552.31, f.camera.fy = 551.08, f.camera.cx = 318.74, f.camera.cy = 243.52;
    f.camera.width_px = 640, f.camera.height_px = 480;
    f.camera.k1 = -0.04127, f.camera.k2 = 0.1834, f.camera.k3 = -0.2915;
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < kObjects; ++i) {
      const Vec3 t(0.8 * u(rng), 0.6 * u(rng), 2.5 + u(rng));
      const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
      Vec6 d;
      d << Vec3::Constant(std::pow(0.002 + 0.004 * (u(rng) + 1), 2)),
          Vec3::Constant(std::pow((1 + 2 * (u(rng) + 1)) * 3.14159 / 180, 2));
      f.poses.push_back({pose_from(t, Eigen::Quaterniond(Eigen::AngleAxisd(3 * u(rng), axis))),
                         d.asDiagonal(), false});
      std::vector<Vec3> box;
      const double s = 0.1 + 0.05 * u(rng);
      for (int k = 0; k < 8; ++k)
        box.emplace_back(k & 1 ? s : -s, k & 2 ? 0.7 * s : -0.7 * s, k & 4 ? 0.5 * s : -0.5 * s);
      f.vertices.push_back(box);
      f.regions.push_back(compute_object_regions(f.camera, f.poses.back(), box));
    }
    return f;
  }();
  return f;
}

const Box kScreen{Vec2(0, 0), Vec2(640, 480)};

void BM_Regions100(benchmark::State& state) {
  const Frame& f = frame();
  for (auto _ : state)
    for (int i = 0; i < kObjects; ++i) {
      ObjectRegions r = compute_object_regions(f.camera, f.poses[i], f.vertices[i]);
      benchmark::DoNotOptimize(r.outer.data());
    }
}

void BM_LabelPlacement100(benchmark::State& state, LabelPolicy policy, bool avoid_other_objects) {
  const Frame& f = frame();
  std::vector<LabelRequest> requests;
  for (const ObjectRegions& r : f.regions) requests.push_back({r.inner, r.outer, Vec2(60, 14)});
  const LabelPlacerOptions options{
      .screen = kScreen, .policy = std::move(policy), .avoid_other_objects = avoid_other_objects};
  int inside = 0, outside = 0, listed = 0;
  for (auto _ : state) {
    const auto labels = place_labels(requests, options);
    benchmark::DoNotOptimize(labels.data());
    inside = outside = listed = 0;
    for (const PlacedLabel& l : labels)
      (l.placement == LabelPlacement::inside_inner    ? inside
       : l.placement == LabelPlacement::outside_outer ? outside
                                                       : listed)++;
  }
  state.counters["inside"] = inside;
  state.counters["outside"] = outside;
  state.counters["listed"] = listed;
}

void BM_Selection100(benchmark::State& state) {
  const Frame& f = frame();
  std::vector<Selectable> objects;
  for (const ObjectRegions& r : f.regions) objects.push_back({r.outer, r.vertices.empty() ? 0 : r.vertices[0].depth_m});
  const Pointer pointer = pointer_with_covariance(Vec2(320, 240), Mat2::Identity() * 100);
  std::size_t candidates = 0;
  for (auto _ : state) {
    const auto by_area = likelihoods_by_area(pointer, objects);
    const auto by_distance = likelihoods_by_distance(pointer, objects);
    const DirectSelection direct = select_direct(by_area, objects);
    const auto targets = layout_indirect_targets(direct.candidates, pointer);
    benchmark::DoNotOptimize(by_distance.data());
    benchmark::DoNotOptimize(targets.data());
    candidates = direct.candidates.size();
  }
  state.counters["candidates"] = static_cast<double>(candidates);
}

}  // namespace

BENCHMARK(BM_Regions100)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_LabelPlacement100, fixed_order, fixed_order_policy(), true)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_LabelPlacement100, most_free_space, most_free_space_policy(), true)
    ->Unit(benchmark::kMicrosecond);
// The same without preferring places that hide no other object: the cost of that search.
BENCHMARK_CAPTURE(BM_LabelPlacement100, fixed_order_own_object_only, fixed_order_policy(), false)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Selection100)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
