// The per-frame AR API (client/ar_view.hpp) against the 2-D viewer, frame by frame, on
// every shipped scene: the same poses, regions, Level-of-Error choices and label places.
#include <gtest/gtest.h>

#include <filesystem>

#include "covtrack/client/ar_view.hpp"
#include "covtrack/scene/scene_graph.hpp"
#include "regions_report.hpp"
#include "scene_ar_view.hpp"
#include "view_labels.hpp"
#include "view_widgets.hpp"

using namespace covtrack;
using namespace covtrack::cli;

namespace {

// The viewer's options and label text, given to the API as `covtrack ar` gives them.
client::ArView ar_view_of(const RegionsModel& model, const cv::Size& screen) {
  auto view = scene_ar_view(model, screen);
  EXPECT_TRUE(view) << view.error().message;
  return std::move(*view);
}

void expect_same_polygon(const client::Polygon& a, const client::Polygon& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << what << " corner " << i;
}

}  // namespace

TEST(ArView, EqualsTheViewerOnEveryShippedScene) {
  int scenes = 0, compared = 0, levels_seen = 0;
  for (const auto& entry : std::filesystem::directory_iterator(COVTRACK_SOURCE_DIR "/config/scenes")) {
    if (entry.path().extension() != ".toml") continue;
    SCOPED_TRACE(entry.path().string());
    auto model = load_regions_model(entry.path().string(), 0);
    ASSERT_TRUE(model) << model.error().message;
    if (model->objects.empty()) continue;
    ++scenes;
    client::TransformGraph graph;
    ASSERT_TRUE(scene::add_scene_transforms(model->scene, graph, 0));
    auto widgets = ViewWidgets::create(model->scene);
    ASSERT_TRUE(widgets);
    const cv::Size screen(model->camera.width_px, model->camera.height_px);
    client::ArView view = ar_view_of(*model, screen);
    // Half-second steps through a 12 s loop: scripted scenes rise and fall through their levels.
    for (int step = 0; step <= 24; ++step) {
      ASSERT_TRUE(scene::report_keyframes(model->scene, graph, step * 0.5, 0));
      auto report = compute_regions(*model, graph, 0, client::ProjectionMethod::unscented);
      ASSERT_TRUE(report) << report.error().message;
      const WidgetFrame w = widgets->update(*report, screen);
      const ViewLabels labels = layout_labels(*report, &w, screen);
      ASSERT_TRUE(view.update(graph, 0));
      const client::ArFrame& frame = view.frame();
      ASSERT_EQ(frame.objects.size(), report->objects.size());
      for (std::size_t i = 0; i < frame.objects.size(); ++i) {
        const client::ArObjectFrame& a = frame.objects[i];
        const client::ObjectRegions& r = report->objects[i].regions;
        const std::string what = report->objects[i].name + " at step " + std::to_string(step);
        EXPECT_EQ(a.regions.valid, r.valid) << what;
        EXPECT_EQ(a.regions.assessment, r.assessment) << what;
        expect_same_polygon(a.regions.outer, r.outer, what + " outer");
        expect_same_polygon(a.regions.inner, r.inner, what + " inner");
        EXPECT_EQ(model->scene.objects[i].augmentations[static_cast<std::size_t>(a.level)], w.augmentations[i]) << what;
        EXPECT_EQ(a.label.placement, labels.placed[i].placement) << what;
        EXPECT_EQ(a.label.box.min, labels.placed[i].box.min) << what;
        EXPECT_EQ(a.label.box.max, labels.placed[i].box.max) << what;
        levels_seen = std::max(levels_seen, a.level);
        ++compared;
      }
    }
  }
  std::printf("%d scenes, %d object frames compared, highest level %d\n", scenes, compared, levels_seen);
  EXPECT_GE(scenes, 4);
  EXPECT_GE(levels_seen, 2);  // the toolbox scene's loop goes through its levels
}

TEST(ArView, AFrameThatCannotBeComputedKeepsTheLastOneAndNamesTheObject) {
  const Pose ahead = pose_from(Vec3(0, 0, 2), Eigen::Quaterniond::Identity());
  client::TransformGraph connected, cut;
  ASSERT_TRUE(connected.add_static_edge("camera", "box", ahead, Mat6::Identity() * 1e-6));
  ASSERT_TRUE(connected.add_static_edge("camera", "crate", ahead, Mat6::Identity() * 1e-6));
  ASSERT_TRUE(cut.add_static_edge("camera", "box", ahead, Mat6::Identity() * 1e-6));
  ASSERT_TRUE(cut.add_static_edge("elsewhere", "crate", ahead));
  client::Camera camera;
  camera.fx = camera.fy = 500;
  camera.cx = 320;
  camera.cy = 240;
  camera.width_px = 640;
  camera.height_px = 480;
  const std::vector<Vec3> cube{{-0.1, -0.1, 0}, {0.1, -0.1, 0}, {0.1, 0.1, 0}, {-0.1, 0.1, 0}, {0, 0, 0.1}};
  auto view = client::ArView::create(camera, "camera", {{"box", "box", cube, {}, 1, {}}, {"crate", "crate", cube, {}, 1, {}}});
  ASSERT_TRUE(view) << view.error().message;
  ASSERT_TRUE(view->update(connected, 7));
  const auto r = view->update(cut, 8);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("object crate: "), std::string::npos) << r.error().message;
  EXPECT_EQ(view->frame().time_us, 7);
  ASSERT_EQ(view->frame().objects.size(), 2u);
  EXPECT_TRUE(view->frame().objects[1].regions.valid);

  const auto bad = client::ArView::create(camera, "camera", {{"box", "box", cube, {5, 1}, 1, {}}});
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("object box: "), std::string::npos) << bad.error().message;
}
