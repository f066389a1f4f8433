// `covtrack calibrate-fiducial` as a user runs it: a board of twelve tags declared as a
// bundle in a config, rendered to PNG files by `covtrack render-tags` (waved in front of
// the camera), calibrated by the command; the written file is read back through the
// device's corner_calibration key, and the printed fit is the camera's known one.
//
// The camera's known values: a tone curve of gamma 2.2 with these print levels and blur
// makes a dark square look smaller by 0.367 px per px of edge blur (measured against the
// true poses by fiducial_board_calibration_test, same formation); a rendered camera is
// the same in every frame, so the apparent scale has no spread about that bias.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cli_support.hpp"
#include "fiducial_config.hpp"

using namespace covtrack::testing;
namespace fs = std::filesystem;

namespace {

constexpr double kKnownBias = -0.367;

class CalibrateFiducialCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("covtrack_calibrate_fiducial_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "frames");
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A device reading the rendered frames, with the board as its bundle; `extra` goes into
  // the device's table.
  fs::path write_config(const std::string& name, const std::string& extra) const {
    std::string text = fmt::format(
        "[devices.cam]\ntype = \"fiducial\"\nparent_frame = \"camera\"\nsource = \"{}\"\n"
        "calibration = \"{}\"\nfamily = \"tag36h11\"\ndecimate = 1.0\n{}\n"
        "[[devices.cam.bundles]]\nname = \"board\"\n",
        (dir_ / "frames" / "frame_%04d.png").string(), COVTRACK_SOURCE_DIR "/config/cameras/rendered_640x480.yml",
        extra);
    // 4 x 3 tags of 40 mm, 64 mm apart (a printed tag36h11 with its white ring is 50 mm).
    for (int id = 0; id < 12; ++id)
      text += fmt::format("[[devices.cam.bundles.tags]]\nid = {}\nsize_m = 0.04\nposition_m = [{}, {}, 0.0]\n", id,
                          (id % 4 - 1.5) * 0.064, (id / 4 - 1.0) * 0.064);
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }

  fs::path dir_;
};

// The number after `label` and its standard error in the command's table: "label  before  fitted +- se".
bool fitted(const std::string& out, const std::string& label, double& value, double& se) {
  std::smatch m;
  const std::regex row(label + R"(\s+\S+\s+(-?[0-9.]+) \+- ([0-9.]+))");
  if (!std::regex_search(out, m, row)) return false;
  value = std::stod(m[1]), se = std::stod(m[2]);
  return true;
}

}  // namespace

// Catches a command that cannot read its frames or board, writes a file the device cannot
// read (or one whose values are not the fit's), or fits something other than the camera.
TEST_F(CalibrateFiducialCli, FitsARenderedBoardAndTheDeviceReadsTheFile) {
  const fs::path config = write_config("board.toml", "");
  // The board 0.5 m ahead, waved: turned up to 30 degrees about each axis and moved up to
  // 4 cm, frame by frame. Print levels and blur as the camera whose bias is known.
  const CliRun render = run_covtrack(fmt::format(
      "render-tags --camera {} --out {} --bundles-from {} --bundle board,0,0,0.5,0,0,0 --frames 30 "
      "--wander-deg 30 --wander-m 0.04 --gamma 2.2 --blur 0.8 --noise 2 --black 12.75 --white 204 "
      "--background 102 --seed 5",
      COVTRACK_SOURCE_DIR "/config/cameras/rendered_640x480.yml", (dir_ / "frames").string(), config.string()));
  ASSERT_EQ(render.exit_code, 0) << render.out;
  ASSERT_TRUE(fs::exists(dir_ / "frames" / "frame_0029.png"));

  const fs::path model = dir_ / "cam_corners.toml";
  const CliRun run = run_covtrack(fmt::format("calibrate-fiducial {} --device cam --board board --out {}",
                                              config.string(), model.string()));
  std::printf("%s", run.out.c_str());
  ASSERT_EQ(run.exit_code, 0) << run.out;
  EXPECT_NE(run.out.find("30 frames read"), std::string::npos) << run.out;
  // The fit's passes settled (a line of its own: "not settled in N passes" otherwise).
  EXPECT_NE(run.out.find("\nsettled in "), std::string::npos) << run.out;

  double bias = 0, bias_se = 0, independent = 0, independent_se = 0, scale = 0, scale_se = 0;
  ASSERT_TRUE(fitted(run.out, "corner_scale_bias_per_blur", bias, bias_se)) << run.out;
  ASSERT_TRUE(fitted(run.out, R"(independent corner noise \(factor\))", independent, independent_se)) << run.out;
  ASSERT_TRUE(fitted(run.out, R"(apparent-scale spread \(factor\))", scale, scale_se)) << run.out;
  EXPECT_NEAR(bias, kKnownBias, 0.03);
  EXPECT_LT(bias_se, 0.01);
  EXPECT_LT(scale, 0.3) << "a rendered camera's apparent scale does not vary from frame to frame";
  // The independent noise: the board fitted 0.80-0.85 of the defaults for this camera.
  EXPECT_GT(independent, 0.5);
  EXPECT_LT(independent, 1.3);

  // The device reads the file through corner_calibration and gets the printed values.
  const fs::path with_file = write_config("with_model.toml", "corner_calibration = \"cam_corners.toml\"");
  auto device = covtrack::fiducial::read_config_device(with_file.string(), "cam");
  ASSERT_TRUE(device.has_value()) << device.error().message;
  EXPECT_EQ(device->corner_calibration.empty(), false);
  EXPECT_NEAR(device->noise.scale_bias_per_blur, bias, 1e-4);
  const covtrack::fiducial::CornerNoiseModel defaults;
  EXPECT_NEAR(device->noise.gain_px / defaults.gain_px, independent, 2e-3);
  EXPECT_NEAR(device->noise.scale_per_blur / defaults.scale_per_blur, scale, 2e-3);

  // Given inline as well, it is an error naming the key.
  const fs::path twice =
      write_config("twice.toml", "corner_calibration = \"cam_corners.toml\"\ncorner_gain_px = 1.0");
  auto both = covtrack::fiducial::read_config_device(twice.string(), "cam");
  ASSERT_FALSE(both.has_value());
  EXPECT_NE(both.error().message.find("corner_gain_px"), std::string::npos) << both.error().message;
}
