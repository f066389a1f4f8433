// The per-frame AR API against its parts called one by one, frame after frame: graph
// queries by name, the regions, Level of Error and a fresh label placement must give
// exactly (bit for bit) what ArView gives with its looked-up frame keys and the memory it
// keeps between frames, on new graphs, on one graph that gains frames, and after a frame
// that failed. And a query by frame keys against the query by names.
#include <gtest/gtest.h>

#include <memory>

#include "bench_frame.hpp"
#include "covtrack/client/ar_view.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

constexpr int kObjects = 300;
const std::vector<double> kThresholds{5, 20, 60};
const std::vector<bool> kListed{false, false, true, true};

// Label sizes that change with the object and its level: inside, outside and list labels.
Vec2 label_box(std::size_t i, const ArObjectFrame& f) { return Vec2(12 + (i % 7) * 9, 6 + f.level % 2 * 4); }

std::string name_of(int i) { return "object" + std::to_string(i); }

// Objects 0, every, 2 every, ... in frame `frame` (their covariances grow with it), below a
// camera that moves when `through_world`.
void add_objects(TransformGraph& g, const test::BenchFrame& f, int frame, bool through_world, int first, int every) {
  if (through_world && !g.has_frame("world")) {
    Pose T = Pose::Identity();
    T.translation() = Vec3(0.01 * frame, -0.02 * frame, 0);
    ASSERT_TRUE(g.add_static_edge("camera", "world", T, Mat6::Identity() * 1e-6 * frame));
  }
  for (int i = first; i < kObjects; i += every)
    ASSERT_TRUE(g.add_static_edge(through_world ? "world" : "camera", name_of(i), f.poses[i].T,
                                  f.poses[i].covariance * (1 + frame)));
}

// What ArView computes, from the parts.
struct Parts {
  std::vector<LevelOfError> levels;
  ArFrame frame;

  Parts() {
    for (int i = 0; i < kObjects; ++i) levels.push_back(*LevelOfError::create(kThresholds, 1));
  }
  void update(const test::BenchFrame& f, const TransformGraph& g, std::int64_t t, const ArViewOptions& options) {
    frame.time_us = t;
    frame.objects.assign(kObjects, {});
    std::vector<LabelRequest> requests(kObjects);
    for (int i = 0; i < kObjects; ++i) {
      ArObjectFrame& o = frame.objects[i];
      o.T_camera_object = *g.query("camera", name_of(i), t);
      o.regions = compute_object_regions(f.camera, o.T_camera_object, f.vertices[i], options.regions);
      o.level = levels[i].update(o.regions.assessment);
      requests[i].size_px = options.label_box(i, o);
      if (!kListed[static_cast<std::size_t>(o.level)]) requests[i].inner = o.regions.inner, requests[i].outer = o.regions.outer;
    }
    const auto labels = place_labels(requests, options.labels);
    for (int i = 0; i < kObjects; ++i) frame.objects[i].label = labels[i];
  }
};

void expect_same(const ArFrame& a, const ArFrame& b, int frame) {
  SCOPED_TRACE("frame " + std::to_string(frame));
  ASSERT_EQ(a.time_us, b.time_us);
  ASSERT_EQ(a.objects.size(), b.objects.size());
  int placements[3] = {0, 0, 0};
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    const ArObjectFrame &x = a.objects[i], &y = b.objects[i];
    SCOPED_TRACE("object " + std::to_string(i));
    EXPECT_EQ(x.T_camera_object.T.matrix(), y.T_camera_object.T.matrix());
    EXPECT_EQ(x.T_camera_object.covariance, y.T_camera_object.covariance);
    EXPECT_EQ(x.regions.outer, y.regions.outer);
    EXPECT_EQ(x.regions.inner, y.regions.inner);
    EXPECT_EQ(x.regions.assessment, y.regions.assessment);
    EXPECT_EQ(x.level, y.level);
    EXPECT_EQ(x.label.box.min, y.label.box.min);
    EXPECT_EQ(x.label.box.max, y.label.box.max);
    EXPECT_EQ(x.label.placement, y.label.placement);
    EXPECT_EQ(x.label.anchored, y.label.anchored);
    EXPECT_EQ(x.label.on_screen, y.label.on_screen);
    EXPECT_EQ(x.label.leader, y.label.leader);
    ++placements[static_cast<int>(x.label.placement)];
  }
  // The frame exercises every kind of place.
  EXPECT_GT(placements[0], 0);
  EXPECT_GT(placements[1], 0);
  EXPECT_GT(placements[2], 0);
}

}  // namespace

TEST(ArView, EqualsItsPartsFrameAfterFrameOnNewAndGrowingGraphs) {
  const test::BenchFrame f = test::make_bench_frame(kObjects);
  std::vector<ArObject> objects;
  for (int i = 0; i < kObjects; ++i) objects.push_back({name_of(i), name_of(i), f.vertices[i], kThresholds, 1, kListed});
  ArViewOptions options;
  options.labels.screen = Box{Vec2(0, 0), Vec2(640, 480)};
  options.label_box = label_box;
  auto view = ArView::create(f.camera, "camera", objects, options);
  ASSERT_TRUE(view) << view.error().message;
  Parts parts;
  int frame = 0;
  // A new graph each frame (keys from the last one must not be used), the camera moving.
  for (; frame < 4; ++frame) {
    auto g = std::make_unique<TransformGraph>();
    add_objects(*g, f, frame, frame % 2 == 1, 0, 1);
    ASSERT_TRUE(view->update(*g, frame));
    parts.update(f, *g, frame, options);
    expect_same(view->frame(), parts.frame, frame);
  }
  // One graph that lacks half the objects (the frame fails and is kept), then has them.
  TransformGraph g;
  add_objects(g, f, frame, false, 0, 2);
  const auto failed = view->update(g, frame);
  ASSERT_FALSE(failed);
  EXPECT_NE(failed.error().message.find("unknown frame 'object1'"), std::string::npos) << failed.error().message;
  expect_same(view->frame(), parts.frame, frame - 1);
  add_objects(g, f, frame, false, 1, 2);
  for (int k = 0; k < 2; ++k, ++frame) {
    ASSERT_TRUE(view->update(g, frame));
    parts.update(f, g, frame, options);
    expect_same(view->frame(), parts.frame, frame);
  }
}

TEST(TransformGraph, AQueryByFrameKeysEqualsTheQueryByNames) {
  const test::BenchFrame f = test::make_bench_frame(20);
  TransformGraph g, other;
  add_objects(g, f, 1, true, 0, 1);
  for (int i = 0; i < 20; ++i) {
    const auto by_name = g.query("camera", name_of(i), 5);
    const auto by_key = g.query(*g.key("camera"), *g.key(name_of(i)), 5);
    ASSERT_TRUE(by_name && by_key);
    EXPECT_EQ(by_name->T.matrix(), by_key->T.matrix());
    EXPECT_EQ(by_name->covariance, by_key->covariance);
    EXPECT_EQ(by_name->unbounded, by_key->unbounded);
  }
  EXPECT_FALSE(g.key("nowhere"));
  ASSERT_TRUE(other.add_static_edge("camera", "object0", Pose::Identity()));
  EXPECT_FALSE(g.query(*other.key("camera"), *g.key("object0"), 5));
  ASSERT_TRUE(g.add_static_edge("elsewhere", "apart", Pose::Identity()));
  const auto apart = g.query(*g.key("camera"), *g.key("apart"), 5);
  ASSERT_FALSE(apart);
  EXPECT_EQ(apart.error().message, g.query("camera", "apart", 5).error().message);
}
