// Scene files: the shipped examples load; every kind of mistake gives file:line.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "covtrack/scene/scene.hpp"
#include "covtrack/scene/scene_graph.hpp"
#include "support/expect_has.hpp"

using covtrack::scene::parse_scene;
using covtrack::scene::scripted_value;
using covtrack::testing::expect_has;

namespace {
std::string error_of(const std::string& text) {
  auto r = parse_scene(text, "bad.toml", ".");
  EXPECT_FALSE(r);
  return r ? std::string() : r.error().message;
}
}  // namespace

TEST(Scene, HeadAndWorldExampleLoads) {
  auto s = covtrack::scene::load_scene(COVTRACK_SOURCE_DIR "/config/scenes/head_and_world.toml");
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->transforms.size(), 5u);
  ASSERT_EQ(s->objects.size(), 2u);
  EXPECT_EQ(s->objects[0].vertices_m.size(), 8u);
  ASSERT_TRUE(s->transforms[1].stream);
  EXPECT_EQ(s->transforms[1].stream->key(), "optical/head");
  EXPECT_NEAR(std::sqrt(s->transforms[1].covariance(3, 3)), 0.0349, 1e-12);
  EXPECT_EQ(s->camera.frame, "camera");
}

TEST(Scene, MistakesGiveFileLineAndKeyPath) {
  const std::string base = "[camera]\nframe = \"c\"\ncalibration = \"c.yml\"\n";
  expect_has(error_of(base + "[[transform]]\nparent = \"a\"\nchild = \"b\"\nsigma_m = [1,1,1]\n"),
             "bad.toml:7:11: transform[0].sigma_m: both sigma_m and sigma_rad are needed");
  expect_has(error_of(base + "[[object]]\nname = \"o\"\nframe = \"f\"\n"),
             "bad.toml:4:1: object[0].box_m: give exactly one of box_m or vertices_m");
  expect_has(error_of(base + "[[object]]\nname = \"o\"\nframe = \"f\"\nvertices_m = [1, 2]\n"),
             "bad.toml:7:14: object[0].vertices_m: needs groups of 3 numbers");
  expect_has(error_of(base + "[[transform]]\nparent = \"a\"\nchild = \"a\"\nsigma_m = [1,1,1]\nsigma_rad = [1,1,1]\n"),
             "transform[0].child: a frame cannot be its own parent");
  expect_has(error_of(base + "[[transform]]\nparent = \"a\"\nchild = \"b\"\nsigma_m = [1,1,1]\nsigma_rad = [1,1,1]\n"
                      "orientation_wxyz = [1, 1, 0, 0]\n"), "bad.toml:9:20: transform[0].orientation_wxyz: norm is");
  expect_has(error_of(base + "[[transform]]\nparent = \"a\"\nchild = \"b\"\nsigma_m = [1,1,1]\nsigma_rad = [1,1,1]\n"
                      "stream = \"nodevice\"\n"), "transform[0].stream: 'nodevice' is not device/sensor");
  expect_has(error_of(base + "confidnce = 3\n"), "bad.toml:4:1: camera.confidnce: unknown key");
  expect_has(error_of("[camera\n"), "bad.toml:1:");
}

TEST(Scene, FusedFrameCombinesBothPathsOfTheTwoPathsExample) {
  auto s = covtrack::scene::load_scene(COVTRACK_SOURCE_DIR "/config/scenes/two_paths.toml");
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_EQ(s->fused.size(), 1u);
  EXPECT_EQ(s->fused[0].via, (std::vector<std::string>{"toolbox_by_wand", "toolbox_by_marker"}));
  covtrack::client::TransformGraph graph;
  const std::int64_t now = 1'000'000;
  ASSERT_TRUE(covtrack::scene::add_scene_transforms(*s, graph, now));
  const auto fused = graph.query("camera", "toolbox", now);
  const auto by_wand = graph.query("camera", "toolbox_by_wand", now);
  const auto by_marker = graph.query("camera", "toolbox_by_marker", now);
  ASSERT_TRUE(fused && by_wand && by_marker);
  // The paths agree on the mean (the example is consistent), and together know more.
  EXPECT_LT((fused->T.translation() - by_wand->T.translation()).norm(), 1e-9);
  EXPECT_LT((fused->T.translation() - by_marker->T.translation()).norm(), 1e-9);
  const auto position_trace = [](const covtrack::Mat6& c) { return c.topLeftCorner<3, 3>().trace(); };
  EXPECT_LT(position_trace(fused->covariance), position_trace(by_wand->covariance));
  EXPECT_LT(position_trace(fused->covariance), position_trace(by_marker->covariance));
}

TEST(Scene, FusedFrameMistakes) {
  const std::string base = "[camera]\nframe = \"c\"\ncalibration = \"c.yml\"\n"
                           "[[transform]]\nparent = \"w\"\nchild = \"a\"\nsigma_m = [1,1,1]\nsigma_rad = [1,1,1]\n";
  expect_has(error_of(base + "[[fused]]\nframe = \"o\"\nparent = \"w\"\nvia = [\"a\"]\ncombiner = \"average\"\n"),
             "bad.toml:13:12: fused[0].combiner:");
  expect_has(error_of(base + "[[fused]]\nframe = \"o\"\nparent = \"w\"\nvia = []\n"), "fused[0].via: names no frame");
  expect_has(error_of(base + "[[fused]]\nframe = \"o\"\nparent = \"w\"\n"), "fused[0].via:");
  // Frames are checked when the graph is built: the message names the fused frame.
  auto s = parse_scene(base + "[[fused]]\nframe = \"o\"\nparent = \"w\"\nvia = [\"a\", \"b\"]\n", "ok.toml", ".");
  ASSERT_TRUE(s) << s.error().message;
  covtrack::client::TransformGraph graph;
  const auto r = covtrack::scene::add_scene_transforms(*s, graph, std::nullopt);
  ASSERT_FALSE(r);
  expect_has(r.error().message, "fused w -> o: transform graph: fused frame 'o': unknown via frame 'b'");
}

TEST(Scene, SchemaDocumentIsUpToDate) {
  std::ifstream in(COVTRACK_SOURCE_DIR "/config/scene_schema.md");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), covtrack::scene::scene_schema_markdown())
      << "regenerate it: covtrack regions --print-schema > config/scene_schema.md";
}

namespace {
const std::string kCamera = "[camera]\nframe = \"c\"\ncalibration = \"c.yml\"\n";
const std::string kTracked =
    "[[transform]]\nparent = \"c\"\nchild = \"t\"\nposition_m = [1, 0, 0]\nsigma_m = [0.1, 0.1, 0.1]\n"
    "sigma_rad = [0.1, 0.1, 0.1]\nstream = \"dev/s0\"\n";
}  // namespace

TEST(Scene, KeyframesInterpolateAndRepeat) {
  const std::string text = kCamera + kTracked +
                           "[[transform.keyframe]]\nt_s = 0\n"
                           "[[transform.keyframe]]\nt_s = 2\nposition_m = [3, 0, 0]\nsigma_scale = 5\n"
                           "[[transform.keyframe]]\nt_s = 4\n";
  auto s = parse_scene(text, "k.toml", ".");
  ASSERT_TRUE(s) << s.error().message;
  const covtrack::scene::SceneTransform& t = s->transforms[0];
  ASSERT_EQ(t.keyframes.size(), 3u);
  EXPECT_EQ(t.keyframes[0].position_m.x(), 1);  // the transform's own position
  const auto at = [&](double time_s) { return covtrack::scene::scripted_value(t, time_s); };
  EXPECT_NEAR(at(1).T_parent_child.translation().x(), 2, 1e-12);
  EXPECT_NEAR(std::sqrt(at(1).covariance(0, 0)), 0.1 * 3, 1e-12);  // sigma scale 1 -> 5, halfway
  EXPECT_NEAR(at(2).T_parent_child.translation().x(), 3, 1e-12);
  EXPECT_NEAR(std::sqrt(at(3).covariance(5, 5)), 0.1 * 3, 1e-12);
  // The last keyframe's time is the period.
  EXPECT_NEAR(at(5).T_parent_child.translation().x(), at(1).T_parent_child.translation().x(), 1e-12);
  EXPECT_NEAR(at(4).T_parent_child.translation().x(), 1, 1e-12);
  EXPECT_NEAR(at(-1).T_parent_child.translation().x(), at(3).T_parent_child.translation().x(), 1e-12);
}

// A keyframe can script the tracker losing the object: from its time to the next keyframe
// the edge's report is LOST, and what hangs below it is infinitely uncertain.
TEST(Scene, KeyframesCanScriptALostTracker) {
  const std::string text = kCamera + kTracked +
                           "[[transform.keyframe]]\nt_s = 0\n"
                           "[[transform.keyframe]]\nt_s = 1\nlost = true\n"
                           "[[transform.keyframe]]\nt_s = 2\n"
                           "[[transform.keyframe]]\nt_s = 3\n";
  auto s = parse_scene(text, "k.toml", ".");
  ASSERT_TRUE(s) << s.error().message;
  const covtrack::scene::SceneTransform& t = s->transforms[0];
  for (double time_s : {0.0, 0.9, 2.0, 2.5, 3.5}) EXPECT_FALSE(scripted_value(t, time_s).lost) << time_s;
  for (double time_s : {1.0, 1.5, 1.99, 4.5}) EXPECT_TRUE(scripted_value(t, time_s).lost) << time_s;

  for (const auto& [time_s, lost] : {std::pair{0.5, false}, std::pair{1.5, true}}) {
    covtrack::client::TransformGraph graph;
    ASSERT_TRUE(covtrack::scene::add_scene_transforms(*s, graph, 0));
    ASSERT_TRUE(covtrack::scene::report_keyframes(*s, graph, time_s, 0));
    auto pose = graph.query("c", "t", 0);
    ASSERT_TRUE(pose) << pose.error().message;
    EXPECT_EQ(pose->unbounded, lost) << time_s;
    if (!lost) {
      EXPECT_NEAR(std::sqrt(pose->covariance(0, 0)), 0.1, 1e-9);
    }
  }
  EXPECT_FALSE(parse_scene(kCamera + kTracked + "[[transform.keyframe]]\nt_s = 0\nlost = 1\n", "k.toml", "."));
}

TEST(Scene, WidgetKeysAndTheirMistakes) {
  const std::string object = "[[object]]\nname = \"o\"\nframe = \"t\"\nbox_m = [1, 1, 1]\n";
  auto s = parse_scene(kCamera + kTracked + object +
                           "level_of_error_px = [4, 9]\naugmentations = [\"outline\", \"region\", \"label\"]\n"
                           "[pointer]\nframe = \"t\"\ntip_m = [0, 0, 0.1]\nlikelihood = \"distance\"\n",
                       "w.toml", ".");
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->objects[0].augmentations.back(), covtrack::scene::Augmentation::label);
  ASSERT_TRUE(s->pointer);
  EXPECT_EQ(s->pointer->likelihood, covtrack::scene::Likelihood::distance);
  EXPECT_EQ(s->pointer->tip_m.z(), 0.1);

  expect_has(error_of(kCamera + object + "level_of_error_px = [4, 9]\n"),
             "object[0].augmentations: 2 thresholds need 3 augmentations, found 1");
  expect_has(error_of(kCamera + object + "level_of_error_px = [9, 4]\naugmentations = [\"outline\", \"region\", \"label\"]\n"),
             "object[0].level_of_error_px: thresholds must be strictly ascending");
  expect_has(error_of(kCamera + object + "level_of_error_px = [4]\naugmentations = [\"outline\", \"arrow\"]\n"),
             "object[0].augmentations: 'arrow' is not outline, region or label");
  expect_has(error_of(kCamera + "[pointer]\nframe = \"t\"\nlikelihood = \"luck\"\n"), "pointer.likelihood");
  expect_has(error_of(kCamera + "[[transform]]\nparent = \"c\"\nchild = \"t\"\nsigma_m = [1,1,1]\nsigma_rad = [1,1,1]\n"
                      "[[transform.keyframe]]\nt_s = 0\n"),
             "transform[0].keyframe: keyframes script a tracker's reports: the transform needs a stream");
  expect_has(error_of(kCamera + kTracked + "[[transform.keyframe]]\nt_s = 1\n"),
             "transform[0].keyframe[0].t_s: the first keyframe is at 0");
  expect_has(error_of(kCamera + kTracked + "[[transform.keyframe]]\nt_s = 0\n[[transform.keyframe]]\nt_s = 0\n"),
             "transform[0].keyframe[1].t_s: keyframes must be in ascending time");
}
