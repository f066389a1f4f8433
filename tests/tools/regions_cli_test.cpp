// `covtrack regions` as a user runs it, on the shipped scene of the dissertation's
// figure 10: the JSON is complete and self-consistent, the head-attached panel's error
// does not come from the head tracker (unlike the dissertation's root model), the
// picture is written, mistakes are reported.
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"

using namespace covtrack::testing;

namespace {

CliRun run(const std::string& args) { return run_covtrack("regions " + args); }

const std::string kScene = COVTRACK_SOURCE_DIR "/config/scenes/head_and_world.toml";

nlohmann::json run_json(const std::string& extra = "") {
  const CliRun r = run(kScene + " --json " + extra);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  return nlohmann::json::parse(r.out, nullptr, false);
}

const nlohmann::json& object(const nlohmann::json& doc, const std::string& name) {
  for (const auto& o : doc["objects"])
    if (o["name"] == name) return o;
  static const nlohmann::json none;
  ADD_FAILURE() << "no object " << name;
  return none;
}

// `covtrack regions --json` on a scene written here: the example camera and a 20 cm box in
// frame "thing", placed by `transform` (the [[transform]] table's position and sigmas).
nlohmann::json run_one_object_scene(const std::string& file_name, const std::string& transform) {
  const std::filesystem::path scene = std::filesystem::temp_directory_path() / file_name;
  std::ofstream(scene) << "[camera]\nframe = \"camera\"\ncalibration = \"" COVTRACK_SOURCE_DIR
                          "/config/cameras/example_640x480.yml\"\n"
                          "[[transform]]\nparent = \"camera\"\nchild = \"thing\"\n"
                       << transform << "[[object]]\nname = \"box\"\nframe = \"thing\"\nbox_m = [0.2, 0.2, 0.2]\n";
  const CliRun r = run(scene.string() + " --json");
  std::filesystem::remove(scene);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  const nlohmann::json doc = nlohmann::json::parse(r.out, nullptr, false);
  EXPECT_FALSE(doc.is_discarded()) << r.out;
  return doc;
}

}  // namespace

TEST(RegionsCli, JsonDescribesEveryHullVertexAndConsistentRegions) {
  const nlohmann::json doc = run_json();
  ASSERT_FALSE(doc.is_discarded());
  ASSERT_EQ(doc["objects"].size(), 2u);
  for (const auto& o : doc["objects"]) {
    SCOPED_TRACE(o["name"].get<std::string>());
    EXPECT_TRUE(o["valid"].get<bool>());
    EXPECT_EQ(o["vertices"].size(), 8u) << "a box has 8 hull vertices";
    EXPECT_GT(o["assessment_px"].get<double>(), 0.0);
    for (const auto& v : o["vertices"]) {
      const auto& c = v["covariance_px2"];
      const double a = c[0][0], b = c[0][1], b2 = c[1][0], d = c[1][1];
      EXPECT_DOUBLE_EQ(b, b2);
      EXPECT_GT(a, 0);
      EXPECT_GE(a * d - b * b, 0);
      EXPECT_TRUE(json_polygon_contains(o["outer_px"], v["mean_px"][0], v["mean_px"][1], 1e-6));
    }
    for (const auto& p : o["inner_px"]) EXPECT_TRUE(json_polygon_contains(o["outer_px"], p[0], p[1], 1e-3));
  }
}

TEST(RegionsCli, HeadAttachedPanelErrorIsNotTheHeadTrackersAsInTheRootModel) {
  const nlohmann::json exact = run_json();
  const nlohmann::json osgar = run_json("--propagation osgar-matrix16");
  const double exact_panel = object(exact, "hud_panel")["assessment_px"];
  const double osgar_panel = object(osgar, "hud_panel")["assessment_px"];
  const double exact_table = object(exact, "table")["assessment_px"];
  std::printf("hud_panel error: exact %.2f px, root model %.2f px (%.1fx); table %.2f px\n",
              exact_panel, osgar_panel, osgar_panel / exact_panel, exact_table);
  // The dissertation's section 4.9.1 model measured 5-78x too large on such a chain.
  EXPECT_GT(osgar_panel, 5 * exact_panel);
  // The world object sees the 2-degree head tracker: far more error than the panel.
  EXPECT_GT(exact_table, 5 * exact_panel);
}

TEST(RegionsCli, TextAndPngOutputs) {
  const std::filesystem::path png = std::filesystem::temp_directory_path() / "covtrack_regions_test.png";
  std::filesystem::remove(png);
  const CliRun r = run(kScene + " --png " + png.string());
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("object hud_panel"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("outer ("), std::string::npos) << r.out;
  std::ifstream in(png, std::ios::binary);
  std::array<unsigned char, 8> magic{};
  in.read(reinterpret_cast<char*>(magic.data()), magic.size());
  EXPECT_EQ(magic, (std::array<unsigned char, 8>{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'}));
  EXPECT_GT(std::filesystem::file_size(png), 1000u);
  std::filesystem::remove(png);
}

TEST(RegionsCli, MistakesAreReportedWithWhere) {
  const std::filesystem::path bad = std::filesystem::temp_directory_path() / "covtrack_bad_scene.toml";
  std::ofstream(bad) << "[camera]\nframe = \"camera\"\ncalibration = \"nope.yml\"\n\n[[object]]\nname = 3\n";
  const CliRun r = run(bad.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.out.find(bad.string() + ":6"), std::string::npos) << r.out;
  std::filesystem::remove(bad);

  const CliRun missing = run("/nonexistent/scene.toml");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.out.find("/nonexistent/scene.toml"), std::string::npos) << missing.out;

  const CliRun unwritable = run(kScene + " --png /nonexistent/dir/out.png");
  EXPECT_NE(unwritable.exit_code, 0);
  EXPECT_NE(unwritable.out.find("/nonexistent/dir/out.png"), std::string::npos) << unwritable.out;
}

TEST(RegionsCli, PrintSchemaIsTheShippedReference) {
  const CliRun r = run("--print-schema");
  ASSERT_EQ(r.exit_code, 0);
  std::ifstream in(COVTRACK_SOURCE_DIR "/config/scene_schema.md");
  const std::string shipped((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(r.out, shipped);
}

TEST(RegionsCli, EveryShippedSceneGivesARegionForEveryObject) {
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(COVTRACK_SOURCE_DIR "/config/scenes")) {
    if (entry.path().extension() != ".toml") continue;
    ++scenes;
    const CliRun r = run(entry.path().string() + " --json");
    ASSERT_EQ(r.exit_code, 0) << entry.path() << "\n" << r.out;
    const nlohmann::json doc = nlohmann::json::parse(r.out, nullptr, false);
    ASSERT_FALSE(doc.is_discarded()) << entry.path();
    EXPECT_FALSE(doc["objects"].empty()) << entry.path();
    for (const auto& o : doc["objects"]) {
      EXPECT_TRUE(o["valid"].get<bool>()) << entry.path() << ": " << o["name"];
      EXPECT_TRUE(o["flags"].empty()) << entry.path() << ": " << o["name"];
    }
  }
  EXPECT_GE(scenes, 2);
}

TEST(RegionsCli, ObjectBehindTheCameraIsFlaggedNotProjected) {
  const nlohmann::json doc = run_one_object_scene("covtrack_behind.toml", "position_m = [0, 0, -2]\n"
                                                  "sigma_m = [0.01, 0.01, 0.01]\nsigma_rad = [0.01, 0.01, 0.01]\n");
  const auto& o = doc["objects"][0];
  EXPECT_FALSE(o["valid"].get<bool>());
  EXPECT_TRUE(o["assessment_px"].is_null());
  EXPECT_EQ(o["flags"], nlohmann::json::array({"behind_camera"}));
  EXPECT_TRUE(o["outer_px"].empty());
  for (const auto& v : o["vertices"]) EXPECT_TRUE(v["mean_px"].is_null());
}

// Depth known to 10% of the distance (a monocular tracker's range, say): the ellipses are
// still drawn, and every vertex and the object say that their shape is in doubt. (The
// shipped scenes above carry no flag.)
TEST(RegionsCli, DepthSpreadLargeAgainstTheDepthIsFlagged) {
  const nlohmann::json doc = run_one_object_scene("covtrack_depth_spread.toml", "position_m = [0, 0, 1.5]\n"
                                                  "sigma_m = [0.005, 0.005, 0.15]\nsigma_rad = [0.01, 0.01, 0.01]\n");
  const auto& o = doc["objects"][0];
  EXPECT_TRUE(o["valid"].get<bool>());
  EXPECT_EQ(o["flags"], nlohmann::json::array({"depth_nonlinear"}));
  EXPECT_FALSE(o["outer_px"].empty());
  for (const auto& v : o["vertices"]) {
    EXPECT_GT(v["depth_sigma_m"].get<double>(), 0.07 * v["depth_m"].get<double>());
    EXPECT_EQ(v["flags"], nlohmann::json::array({"depth_nonlinear"}));
  }
}
