// Frame time of `covtrack ar` with 50 objects at 640x480 against the 2-D viewer's whole
// frame for the same scene, each without window or file output:
//   View2D: regions, widgets, labels and drawing into an OpenCV image (what `view` does);
//   Ar3D:   the per-frame API (ArView), the scene update, an OpenGL frame off screen and
//           its pixels read back (what `ar --video` does per frame).
// Both need no display except Ar3D (Mesa under Xvfb). Run by hand:
//   tests/with_xvfb.sh taskset -c 0 build/tests/tools/bench_ar ; ratio = Ar3D / View2D.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include <benchmark/benchmark.h>

#include "ar_models.hpp"
#include "covtrack/osg/ar_scene.hpp"
#include "covtrack/osg/ar_viewer.hpp"
#include "covtrack/scene/scene_graph.hpp"
#include "region_drawing.hpp"
#include "regions_report.hpp"
#include "scene_ar_view.hpp"
#include "view_widgets.hpp"

using namespace covtrack;
using namespace covtrack::cli;

namespace {

constexpr int kColumns = 10, kRows = 5;  // 50 boxes on a wall 1.5 m away

RegionsModel& model() {
  static RegionsModel m = [] {
    const auto path = std::filesystem::temp_directory_path() / "covtrack_bench_ar_scene.toml";
    std::ofstream scene(path);
    scene << "[camera]\nframe = \"camera\"\ncalibration = \"" COVTRACK_SOURCE_DIR "/config/cameras/rendered_640x480.yml\"\n";
    for (int r = 0; r < kRows; ++r)
      for (int c = 0; c < kColumns; ++c) {
        const int i = r * kColumns + c;
        scene << "[[transform]]\nparent = \"camera\"\nchild = \"f" << i << "\"\nposition_m = [" << 0.16 * (c - 4.5)
              << ", " << 0.16 * (r - 2) << ", 1.5]\nrotation_rpy_deg = [20, 30, 0]\n"
              << "sigma_m = [0.002, 0.002, 0.004]\nsigma_rad = [0.01, 0.01, 0.01]\n"
              << "[[object]]\nname = \"box" << i << "\"\nframe = \"f" << i << "\"\nbox_m = [0.08, 0.06, 0.05]\n";
      }
    scene.close();
    auto loaded = load_regions_model(path.string(), 0.95);
    std::filesystem::remove(path);
    if (!loaded) std::fprintf(stderr, "bench_ar: %s\n", loaded.error().message.c_str()), std::exit(1);
    return std::move(*loaded);
  }();
  return m;
}

client::TransformGraph& graph() {
  static client::TransformGraph g;
  static const bool ready = scene::add_scene_transforms(model().scene, g, 0).has_value();
  (void)ready;
  return g;
}

cv::Size screen() { return {model().camera.width_px, model().camera.height_px}; }

void BM_View2D(benchmark::State& state) {
  auto widgets = *ViewWidgets::create(model().scene);
  cv::Mat image(screen(), CV_8UC3);
  for (auto _ : state) {
    const auto report = compute_regions(model(), graph(), 0, client::ProjectionMethod::unscented);
    const WidgetFrame w = widgets.update(*report, screen());
    image = cv::Scalar(40, 40, 40);
    draw_regions(image, *report, &w);
    benchmark::DoNotOptimize(image.data);
  }
}
BENCHMARK(BM_View2D)->Unit(benchmark::kMillisecond);

void BM_Ar3D(benchmark::State& state) {
  auto view = scene_ar_view(model(), screen());
  ar::ArScene scene(model().camera);
  for (std::size_t i = 0; i < model().scene.objects.size(); ++i) scene.add_object(*ar_models(model().scene.objects[i], i));
  auto viewer = ar::ArViewer::open(scene, ar::ArViewer::Output::offscreen);
  if (!view || !viewer) {
    state.SkipWithError(viewer ? "no ArView" : viewer.error().message.c_str());
    return;
  }
  std::vector<std::string> labels;
  for (const auto& o : model().scene.objects) labels.push_back(o.name);
  scene.set_video(cv::Mat(screen(), CV_8UC3, cv::Scalar(40, 40, 40)));
  for (auto _ : state) {
    (void)view->update(graph(), 0);
    scene.update(view->frame(), labels);
    (*viewer)->frame();
    benchmark::DoNotOptimize((*viewer)->image().data);
  }
}
BENCHMARK(BM_Ar3D)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
