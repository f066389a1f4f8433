// Widget cost per frame against the regions they use: 100 objects, each region computed
// (UT, the default) vs label placement for all of them vs selection (likelihoods by area
// and by distance, direct selection, indirect targets). Single thread.
// And the per-frame AR API (ar_view.hpp: graph queries, regions, Level of Error, labels)
// for 1,000 objects against their regions alone.
// Run: taskset -c 0 build/tests/client/bench_widgets ; ratios = widget time / regions time.
#include <random>

#include <benchmark/benchmark.h>

#include "bench_frame.hpp"
#include "covtrack/client/ar_view.hpp"
#include "covtrack/client/label_placer.hpp"
#include "covtrack/client/selection.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

constexpr int kObjects = 100;

struct Frame : test::BenchFrame {
  std::vector<ObjectRegions> regions;  // computed once, for the widget benchmarks
};

const Frame& frame() {
  static const Frame f = [] {
    Frame f{test::make_bench_frame(kObjects), {}};
    for (int i = 0; i < kObjects; ++i)
      f.regions.push_back(compute_object_regions(f.camera, f.poses[i], f.vertices[i]));
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

// The same kind of objects, up to 1,000, each on its own edge from the camera.
constexpr int kArObjects = 1000;
const test::BenchFrame& ar_frame() {
  static const test::BenchFrame f = test::make_bench_frame(kArObjects);
  return f;
}

void BM_RegionsAlone(benchmark::State& state) {
  const test::BenchFrame& f = ar_frame();
  const int n = static_cast<int>(state.range(0));
  ObjectRegions r;
  for (auto _ : state)
    for (int i = 0; i < n; ++i) {
      compute_object_regions(f.camera, f.poses[i], f.vertices[i], {}, r);
      benchmark::DoNotOptimize(r.outer.data());
    }
}

std::string object_name(std::size_t i) { return "object" + std::to_string(i); }

// The frame's first n objects into `graph` (a graph holds a mutex: filled, not returned),
// each a static edge from the camera, as a scene file makes them.
void add_objects(TransformGraph& graph, const test::BenchFrame& f, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    (void)graph.add_static_edge("camera", object_name(i), f.poses[i].T, f.poses[i].covariance);
}

// The step between the two: each object's pose queried from a graph (by keys, as ArView
// does) and its regions computed into its own output. What it adds to the regions alone is
// the queries' cost, their memory traffic included (regions into per-object outputs
// without the queries measured the same as the regions alone).
void BM_QueriesAndRegions(benchmark::State& state) {
  const test::BenchFrame& f = ar_frame();
  const auto n = static_cast<std::size_t>(state.range(0));
  TransformGraph graph;
  add_objects(graph, f, n);
  std::vector<TransformGraph::FrameKey> keys;
  for (std::size_t i = 0; i < n; ++i) keys.push_back(*graph.key(object_name(i)));
  const TransformGraph::FrameKey camera = *graph.key("camera");
  std::vector<ObjectRegions> regions(n);
  for (auto _ : state)
    for (std::size_t i = 0; i < n; ++i) {
      const auto T = graph.query(camera, keys[i], 0);
      compute_object_regions(f.camera, *T, f.vertices[i], {}, regions[i]);
      benchmark::DoNotOptimize(regions[i].outer.data());
    }
}

void BM_ArView(benchmark::State& state) {
  const test::BenchFrame& f = ar_frame();
  const auto n = static_cast<std::size_t>(state.range(0));
  TransformGraph graph;
  add_objects(graph, f, n);
  std::vector<ArObject> objects;
  for (std::size_t i = 0; i < n; ++i)
    objects.push_back({object_name(i), object_name(i), f.vertices[i], {20, 60}, 1, {false, false, true}});
  ArViewOptions options;
  options.labels.screen = kScreen;
  auto view = ArView::create(f.camera, "camera", std::move(objects), std::move(options));
  int listed = 0;
  for (auto _ : state) {
    (void)view->update(graph, 0);
    benchmark::DoNotOptimize(view->frame().objects.data());
  }
  for (const ArObjectFrame& o : view->frame().objects) listed += o.label.placement == LabelPlacement::corner_list;
  state.counters["listed"] = listed;
}

}  // namespace

BENCHMARK(BM_RegionsAlone)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QueriesAndRegions)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ArView)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);
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
