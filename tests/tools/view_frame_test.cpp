// One frame of `covtrack view` at a time, on the shipped tool-box scene (after the
// dissertation's figures 1, 18 and 19, docs/background.md): its scripted error rises and
// falls over a 12 s loop, so the widgets must follow it: Level of Error up and back down
// without flicker, labels from inside the drawers to leader lines and back, the pointer
// selecting the drawer under it.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "covtrack/client/convex_polygon.hpp"
#include "covtrack/client/regions.hpp"
#include "covtrack/scene/scene_graph.hpp"
#include "region_drawing.hpp"
#include "regions_report.hpp"
#include "view_labels.hpp"
#include "view_widgets.hpp"

using namespace covtrack;
using namespace covtrack::cli;
using scene::Augmentation;

namespace {

struct Frame {
  double time_s = 0;
  RegionsReport report;
  WidgetFrame widgets;
  ViewLabels labels;
};

// A legend of 9 lines (a scene with several streams) reaches up past the lowest drawers.
int label_bottom(const cv::Size& screen) { return screen.height - legend_height_px(9, screen.height); }

// Every frame of one loop at `fps`, as the view computes them (fixed scene values).
std::vector<Frame> toolbox_loop(double fps) {
  auto model = load_regions_model(COVTRACK_SOURCE_DIR "/config/scenes/toolbox.toml", 0);
  EXPECT_TRUE(model) << model.error().message;
  client::TransformGraph graph;
  EXPECT_TRUE(scene::add_scene_transforms(model->scene, graph, 0));
  auto widgets = ViewWidgets::create(model->scene);
  EXPECT_TRUE(widgets);
  const cv::Size screen(model->camera.width_px, model->camera.height_px);
  std::vector<Frame> frames;
  for (int i = 0; i <= 12 * fps; ++i) {
    Frame f;
    f.time_s = i / fps;
    EXPECT_TRUE(scene::report_keyframes(model->scene, graph, f.time_s, 0));
    auto report = compute_regions(*model, graph, 0, client::ProjectionMethod::unscented);
    EXPECT_TRUE(report) << report.error().message;
    f.report = std::move(*report);
    f.widgets = widgets->update(f.report, screen);
    // As the view lays them out: clear of its legend at the bottom (here a long one).
    f.labels = layout_labels(f.report, &f.widgets, cv::Size(screen.width, label_bottom(screen)));
    frames.push_back(std::move(f));
  }
  return frames;
}

const std::vector<Frame>& loop() {
  static const std::vector<Frame> frames = toolbox_loop(15);
  return frames;
}

int object_named(const RegionsReport& report, const std::string& name) {
  for (std::size_t i = 0; i < report.objects.size(); ++i)
    if (report.objects[i].name == name) return static_cast<int>(i);
  ADD_FAILURE() << "no object " << name;
  return 0;
}

}  // namespace

TEST(ViewFrame, LevelOfErrorRisesAndFallsWithoutFlicker) {
  const std::vector<Frame>& frames = loop();
  ASSERT_EQ(frames.front().report.objects.size(), 8u);
  for (std::size_t object = 0; object < 8; ++object) {
    std::vector<Augmentation> sequence;
    double lowest = INFINITY, highest = 0;
    for (const Frame& f : frames) {
      const double a = f.report.objects[object].regions.assessment;
      lowest = std::min(lowest, a);
      highest = std::max(highest, a);
      const Augmentation now = f.widgets.augmentations[object];
      if (sequence.empty() || sequence.back() != now) {
        // A change happens only past its threshold (6 and 30 px, margin 1.5 going down).
        if (!sequence.empty() && now > sequence.back()) {
          EXPECT_GE(a, now == Augmentation::region ? 6 : 30);
        }
        if (!sequence.empty() && now < sequence.back()) {
          EXPECT_LT(a, now == Augmentation::outline ? 4.5 : 28.5);
        }
        sequence.push_back(now);
      }
    }
    EXPECT_LT(lowest, 4.5) << "the loop must start below the first threshold";
    EXPECT_GT(highest, 30) << "and rise above the last";
    const std::vector<Augmentation> expected = {Augmentation::outline, Augmentation::region, Augmentation::label,
                                                Augmentation::region, Augmentation::outline};
    EXPECT_EQ(sequence, expected) << "object " << object;
  }
}

TEST(ViewFrame, LabelsGoFromInsideTheDrawersToLeaderLinesToTheListAndBack) {
  using client::LabelPlacement;
  bool leader_seen = false;
  for (const Frame& f : loop()) {
    const auto& placed = f.labels.placed;
    for (std::size_t i = 0; i < placed.size(); ++i) {
      const client::ObjectRegions& r = f.report.objects[i].regions;
      if (placed[i].placement != LabelPlacement::corner_list) {
        EXPECT_LE(placed[i].box.max.y(), label_bottom({640, 480}) + 1e-9) << "under the legend at " << f.time_s;
      }
      if (placed[i].placement == LabelPlacement::inside_inner) {
        for (const client::Vec2& corner : client::box_polygon(placed[i].box))
          EXPECT_TRUE(client::polygon_contains(r.inner, corner, 1e-6)) << f.time_s << " s, object " << i;
      }
      if (placed[i].placement == LabelPlacement::outside_outer) {
        EXPECT_FALSE(client::box_meets_convex(placed[i].box, r.outer)) << f.time_s << " s, object " << i;
        EXPECT_TRUE(placed[i].leader);
        leader_seen = true;
      }
      for (std::size_t j = 0; j < i; ++j)
        EXPECT_FALSE(client::boxes_overlap(placed[i].box, placed[j].box)) << f.time_s << " s, labels " << i << ", " << j;
    }
  }
  EXPECT_TRUE(leader_seen) << "as the error rises, some label must leave its drawer for a leader line";
  const auto placements_at = [](double t) {
    std::vector<LabelPlacement> out;
    for (const Frame& f : loop())
      if (std::abs(f.time_s - t) < 1e-9)
        for (const auto& p : f.labels.placed) out.push_back(p.placement);
    return out;
  };
  // Smallest error: every label inside its drawer; largest: the Level of Error lists them.
  EXPECT_EQ(placements_at(0), std::vector<LabelPlacement>(8, LabelPlacement::inside_inner));
  EXPECT_EQ(placements_at(7), std::vector<LabelPlacement>(8, LabelPlacement::corner_list));
  EXPECT_EQ(placements_at(12), std::vector<LabelPlacement>(8, LabelPlacement::inside_inner));
}

TEST(ViewFrame, PointerSelectsTheDrawerUnderItAndSpreadsTargetsWhenAmbiguous) {
  const Frame& start = loop().front();
  ASSERT_TRUE(start.widgets.pointer);
  const int wrenches = object_named(start.report, "wrenches");
  ASSERT_TRUE(start.widgets.selection.selected);
  EXPECT_EQ(*start.widgets.selection.selected, wrenches);
  EXPECT_FALSE(start.widgets.selection.ambiguous());
  EXPECT_GT(start.widgets.likelihoods[wrenches], 0.99);
  EXPECT_TRUE(start.widgets.targets.empty());

  bool ambiguous_seen = false;
  for (const Frame& f : loop()) {
    const WidgetFrame& w = f.widgets;
    for (double p : w.likelihoods) {
      EXPECT_GE(p, 0);
      EXPECT_LE(p, 1 + 1e-9);
    }
    if (!w.selection.ambiguous()) continue;
    ambiguous_seen = true;
    ASSERT_EQ(w.targets.size(), w.selection.candidates.size()) << f.time_s;
    // Each target shows its object's whole name.
    for (const client::SelectionTarget& t : w.targets) {
      const std::string& name = f.report.objects[static_cast<std::size_t>(t.object)].name;
      const int text = cv::getTextSize(name, kLabelFont, kLabelFontScale, 1, nullptr).width;
      EXPECT_GE(t.box.width(), text + 2 * kLabelPad - 1e-9) << name << " at " << f.time_s << " s";
    }
    // Indirect targets: any two farther apart than the pointer's region can reach.
    const double error = client::pointer_error_px(*w.pointer);
    for (std::size_t i = 0; i < w.targets.size(); ++i)
      for (std::size_t j = 0; j < i; ++j) {
        const client::Box &a = w.targets[i].box, &b = w.targets[j].box;
        const double gap_x = std::max(a.min.x() - b.max.x(), b.min.x() - a.max.x());
        const double gap_y = std::max(a.min.y() - b.max.y(), b.min.y() - a.max.y());
        EXPECT_GE(std::max(gap_x, gap_y), 2 * error - 1e-6) << f.time_s << " s";
      }
  }
  EXPECT_TRUE(ambiguous_seen) << "the pointer crosses between drawers while the error is large";
}
