// Frame time of `covtrack view` on the tool-box scene (8 drawers, a pointer) against the
// region computation alone: regions; regions + widgets (Level of Error, selection, label
// placement); and the whole frame as the view draws it (plain background, fills,
// ellipses, regions, labels, legend). Without window or file output. Single thread.
// Run: taskset -c 0 build/tests/tools/bench_view ; ratio = frame time / regions time.
#include <benchmark/benchmark.h>

#include "covtrack/scene/scene_graph.hpp"
#include "region_drawing.hpp"
#include "regions_report.hpp"
#include "view_labels.hpp"
#include "view_widgets.hpp"

using namespace covtrack;
using namespace covtrack::cli;

namespace {

// The scene at `time_s` of its loop: 4 s is mid-rise (shaded regions, leader lines).
struct Setup {
  RegionsModel model;
  client::TransformGraph graph;
  cv::Size screen;
};

Setup& setup() {
  static Setup s{*load_regions_model(COVTRACK_SOURCE_DIR "/config/scenes/toolbox.toml", 0), client::TransformGraph(), {}};
  static const bool ready = [] {
    (void)scene::add_scene_transforms(s.model.scene, s.graph, 0);
    (void)scene::report_keyframes(s.model.scene, s.graph, 4.0, 0);
    s.screen = cv::Size(s.model.camera.width_px, s.model.camera.height_px);
    return true;
  }();
  (void)ready;
  return s;
}

void BM_RegionsAlone(benchmark::State& state) {
  Setup& s = setup();
  for (auto _ : state) benchmark::DoNotOptimize(compute_regions(s.model, s.graph, 0, client::ProjectionMethod::unscented));
}
BENCHMARK(BM_RegionsAlone)->Unit(benchmark::kMicrosecond);

void BM_RegionsAndWidgets(benchmark::State& state) {
  Setup& s = setup();
  auto widgets = *ViewWidgets::create(s.model.scene);
  for (auto _ : state) {
    const auto report = compute_regions(s.model, s.graph, 0, client::ProjectionMethod::unscented);
    const WidgetFrame w = widgets.update(*report, s.screen);
    benchmark::DoNotOptimize(layout_labels(*report, &w, s.screen));
  }
}
BENCHMARK(BM_RegionsAndWidgets)->Unit(benchmark::kMicrosecond);

void BM_WholeFrame(benchmark::State& state) {
  Setup& s = setup();
  auto widgets = *ViewWidgets::create(s.model.scene);
  cv::Mat image(s.screen, CV_8UC3);
  for (auto _ : state) {
    const auto report = compute_regions(s.model, s.graph, 0, client::ProjectionMethod::unscented);
    const WidgetFrame w = widgets.update(*report, s.screen);
    image = cv::Scalar(40, 40, 40);
    draw_regions(image, *report, &w);
    draw_legend(image, {"95% regions: ellipses blue, outer green, inner white", "camera -> toolbox [fiducial/tag0]"});
    benchmark::DoNotOptimize(image.data);
  }
}
BENCHMARK(BM_WholeFrame)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
