// Transform tables: a scene's static edges from a CSV file give the same graph as the
// same edges written as [[transform]] tables, and every mistake names file:line and column.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "covtrack/scene/scene.hpp"
#include "covtrack/scene/scene_graph.hpp"
#include "covtrack/scene/transform_table.hpp"
#include "support/expect_has.hpp"

using namespace covtrack;
using scene::kTransformTableHeader;
using scene::parse_transform_table;
using covtrack::testing::expect_has;

namespace {

std::string table_error(const std::string& rows) {
  auto r = parse_transform_table(std::string(kTransformTableHeader) + "\n" + rows, "t.csv");
  EXPECT_FALSE(r) << rows;
  return r ? std::string() : r.error().message;
}

class TransformTableFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / fmt::format("transform_table_test_{}", getpid());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return (dir_ / name).string();
  }
  std::filesystem::path dir_;
};

const char* kCameraSection = "[camera]\nframe = \"f0\"\ncalibration = \"c.yml\"\n";

// T_f0_fN and its covariance through a graph built from the scene.
client::UncertainPose chain_end(const scene::Scene& s, const std::string& leaf) {
  client::TransformGraph graph;
  auto added = scene::add_scene_transforms(s, graph, std::nullopt);
  EXPECT_TRUE(added) << added.error().message;
  auto pose = graph.query("f0", leaf, 0);
  EXPECT_TRUE(pose) << pose.error().message;
  return pose ? *pose : client::UncertainPose{};
}

}  // namespace

TEST_F(TransformTableFiles, RowsGiveTheSameChainAsTransformTables) {
  // Links with every column different, so a swapped column shows.
  std::string rows = std::string("# a comment, then the header\n\n") + std::string(kTransformTableHeader) + "\n";
  std::string tables = kCameraSection;
  for (int i = 0; i < 50; ++i) {
    const double x = 0.01 * i, y = -0.002 * i, z = 0.03, roll = 1.5 + i, pitch = -2.0, yaw = 0.1 * i;
    const double sx = 1e-4 * (1 + i % 3), sy = 2e-4, sz = 3e-4, sr = 4e-4, sp = 5e-4 * (1 + i % 2), syaw = 6e-4;
    rows += fmt::format("f{},f{},{},{},{},{},{},{},{},{},{},{},{},{}\r\n", i, i + 1, x, y, z, roll, pitch, yaw,
                        sx, sy, sz, sr, sp, syaw);
    tables += fmt::format("[[transform]]\nparent = \"f{}\"\nchild = \"f{}\"\nposition_m = [{}, {}, {}]\n"
                          "rotation_rpy_deg = [{}, {}, {}]\nsigma_m = [{}, {}, {}]\nsigma_rad = [{}, {}, {}]\n",
                          i, i + 1, x, y, z, roll, pitch, yaw, sx, sy, sz, sr, sp, syaw);
  }
  write("links.csv", rows);
  const std::string scene_path =
      write("chain.toml", "transform_tables = [\"links.csv\"]\n" + std::string(kCameraSection));
  auto from_rows = scene::load_scene(scene_path);
  ASSERT_TRUE(from_rows) << from_rows.error().message;
  auto from_tables = scene::parse_scene(tables, "tables.toml", dir_.string());
  ASSERT_TRUE(from_tables) << from_tables.error().message;
  ASSERT_EQ(from_rows->transforms.size(), 50u);
  for (std::size_t i = 0; i < 50; ++i) {
    EXPECT_EQ(from_rows->transforms[i].child, from_tables->transforms[i].child);
    EXPECT_TRUE(from_rows->transforms[i].T_parent_child.isApprox(from_tables->transforms[i].T_parent_child, 1e-15));
    EXPECT_TRUE(from_rows->transforms[i].covariance.isApprox(from_tables->transforms[i].covariance, 1e-15));
    EXPECT_FALSE(from_rows->transforms[i].stream);
  }
  const client::UncertainPose a = chain_end(*from_rows, "f50"), b = chain_end(*from_tables, "f50");
  EXPECT_TRUE(a.T.isApprox(b.T, 1e-12));
  EXPECT_TRUE(a.covariance.isApprox(b.covariance, 1e-12));
  EXPECT_GT(a.covariance(0, 0), 0);
}

TEST_F(TransformTableFiles, TablesAddToTheScenesOwnTransforms) {
  write("more.csv", std::string(kTransformTableHeader) + "\nf1,f2,0,0,1,0,0,0,0.1,0.1,0.1,0,0,0\n");
  const std::string scene_path = write(
      "mixed.toml", "transform_tables = [\"more.csv\"]\n" + std::string(kCameraSection) +
                        "[[transform]]\nparent = \"f0\"\nchild = \"f1\"\nposition_m = [1, 0, 0]\n"
                        "sigma_m = [0, 0, 0]\nsigma_rad = [0, 0, 0]\n");
  auto s = scene::load_scene(scene_path);
  ASSERT_TRUE(s) << s.error().message;
  ASSERT_EQ(s->transforms.size(), 2u);
  const client::UncertainPose end = chain_end(*s, "f2");
  EXPECT_TRUE(end.T.translation().isApprox(Vec3(1, 0, 1)));
  EXPECT_NEAR(end.covariance(2, 2), 0.01, 1e-15);
}

TEST_F(TransformTableFiles, AMissingTableIsNamedWithTheScenesKey) {
  const std::string scene_path = write("s.toml", "transform_tables = [\"absent.csv\"]\n" + std::string(kCameraSection));
  auto s = scene::load_scene(scene_path);
  ASSERT_FALSE(s);
  expect_has(s.error().message, "s.toml:1:");
  expect_has(s.error().message, "transform_tables");
  expect_has(s.error().message, "absent.csv");
}

// A table is bulk data: larger than a config file may be (4 MiB), it still loads.
TEST_F(TransformTableFiles, ATableLargerThanAConfigFileLoads) {
  std::string rows = std::string(kTransformTableHeader) + "\n";
  const int links = 60'000;
  for (int i = 0; i < links; ++i)
    rows += fmt::format("f{},f{},0.001,0.002,0.003,0.1,0.2,0.3,0.0001,0.0001,0.0001,0.0001,0.0001,0.0001\n", i, i + 1);
  ASSERT_GT(rows.size(), std::size_t(4) << 20);
  write("big.csv", rows);
  const std::string scene_path = write("s.toml", "transform_tables = [\"big.csv\"]\n" + std::string(kCameraSection));
  auto s = scene::load_scene(scene_path);
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->transforms.size(), std::size_t(links));
}

TEST(TransformTable, MistakesGiveFileLineAndColumn) {
  expect_has(table_error("a,b,0,0,0,0,0,0,0,0,0,0,0\n"), "t.csv:2: 13 columns, expected 14");
  expect_has(table_error("a,b,0,0,0,0,0,0,0,0,0,0,0,0,0\n"), "t.csv:2: 15 columns, expected 14");
  expect_has(table_error("a,b,0,0,zero,0,0,0,0,0,0,0,0,0\n"), "t.csv:2: column z_m: 'zero' is not a finite number");
  expect_has(table_error("a,b,0,0,0,nan,0,0,0,0,0,0,0,0\n"), "column roll_deg: 'nan' is not a finite number");
  expect_has(table_error("a,b,0,0,0,0,0,inf,0,0,0,0,0,0\n"), "column yaw_deg: 'inf' is not a finite number");
  expect_has(table_error("a,b,0,0,0,0,0,0,0,0,0,0,0,1e400\n"), "column sigma_yaw_rad: '1e400' is not a finite number");
  expect_has(table_error("a,b,0,0,0,0,0,0,-1,0,0,0,0,0\n"), "column sigma_x_m: -1 is outside [0, 10]");
  expect_has(table_error("a,b,0,0,0,0,400,0,0,0,0,0,0,0\n"), "column pitch_deg: 400 is outside [-360, 360]");
  expect_has(table_error("a,b,0,0,0,0,0,0,0,0,0,0,0,0\n\"c\",b,0,0,0,0,0,0,0,0,0,0,0,0\n"),
             "t.csv:3: column parent: '\"c\"' is not a frame name");
  expect_has(table_error("a,,0,0,0,0,0,0,0,0,0,0,0,0\n"), "column child: '' is not a frame name");
  expect_has(table_error("a,a,0,0,0,0,0,0,0,0,0,0,0,0\n"), "t.csv:2: 'a' cannot be its own parent");
  expect_has(table_error("a,b,0,0,0,0,0,0,0,0,0,0,0,0x1\n"), "column sigma_yaw_rad: '0x1' is not a finite number");

  auto no_header = parse_transform_table("a,b,0,0,0,0,0,0,0,0,0,0,0,0\n", "t.csv");
  ASSERT_FALSE(no_header);
  expect_has(no_header.error().message, "t.csv:1: the header must be exactly 'parent,child,x_m");
  auto empty = parse_transform_table("# nothing\n", "t.csv");
  ASSERT_FALSE(empty);
  expect_has(empty.error().message, "t.csv:1: no header");

  // Many bad rows: the first ten are named, then how many more.
  std::string bad;
  for (int i = 0; i < 25; ++i) bad += "a,b,x,0,0,0,0,0,0,0,0,0,0,0\n";
  const std::string many = table_error(bad);
  expect_has(many, "t.csv:11: column x_m");
  EXPECT_EQ(many.find("t.csv:12:"), std::string::npos) << many;
  expect_has(many, "... and 15 more errors");
}
