// Scene files: the shipped examples load; every kind of mistake gives file:line.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "covtrack/scene/scene.hpp"

using covtrack::scene::parse_scene;

namespace {
std::string error_of(const std::string& text) {
  auto r = parse_scene(text, "bad.toml", ".");
  EXPECT_FALSE(r);
  return r ? std::string() : r.error().message;
}
void expect_has(const std::string& msg, const std::string& part) {
  EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
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

TEST(Scene, SchemaDocumentIsUpToDate) {
  std::ifstream in(COVTRACK_SOURCE_DIR "/config/scene_schema.md");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), covtrack::scene::scene_schema_markdown())
      << "regenerate it: covtrack regions --print-schema > config/scene_schema.md";
}
