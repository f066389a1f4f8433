// `covtrackd --check` opens the files each fiducial device names: a missing image
// folder, first image, video file or calibration is reported at its key's
// file:line:column with what it was taken for and where it was looked for, and the exit
// code is 2 as for every other config problem. A camera is not opened (a config written
// for one checks on a machine without it), and a start checks none of it: a camera
// plugged in later is picked up by the driver's restarts.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "config.hpp"

namespace fs = std::filesystem;

namespace {

struct CheckRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// `covtrackd --check` of a config file.
CheckRun check_file(const std::string& config) {
  const std::string cmd = std::string(COVTRACK_BINARY_DIR "/server/covtrackd --check --config ") + config + " 2>&1";
  CheckRun run;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return run;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) run.output += buf;
  const int status = pclose(p);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// The config file dir/check.toml with one fiducial device of this source, checked by
// the daemon binary.
CheckRun check(const fs::path& dir, const std::string& source, std::string* config_path = nullptr) {
  const fs::path config = dir / "check.toml";
  std::ofstream(config) << "[devices.eye]\n"
                           "type = \"fiducial\"\n"
                           "source = \"" << source << "\"\n"
                           "calibration = \"" COVTRACK_SOURCE_DIR "/config/cameras/rendered_640x480.yml\"\n"
                           "[[devices.eye.tags]]\nid = 0\nsize_m = 0.16\n";
  if (config_path) *config_path = config.string();
  return check_file(config.string());
}

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("fiducial_check_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace

TEST(FiducialCheck, MissingSourcesAreReportedAtTheirKeyWithExitCode2) {
  const fs::path dir = fresh_dir("missing");
  struct Case {
    std::string source;    // as written in the config (relative to its folder)
    std::string expected;  // the error after "file:3:10: devices.eye.source: "
  };
  const std::string d = dir.string();
  const std::vector<Case> cases = {
      {"frames/frame_%04d.png",
       "image sequence '" + d + "/frames/frame_%04d.png': folder '" + d + "/frames' does not exist"},
      {"frame_%04d.png", "image sequence '" + d + "/frame_%04d.png': neither '" + d + "/frame_0000.png' nor '" +
                             d + "/frame_0001.png' exists"},
      {"take.mp4", "video file '" + d + "/take.mp4' does not exist"},
  };
  for (const Case& c : cases) {
    std::string config;
    const CheckRun run = check(dir, c.source, &config);
    EXPECT_EQ(run.exit_code, 2) << c.source << ":\n" << run.output;
    // The value starts on line 3, column 10 of the file written above.
    EXPECT_NE(run.output.find(config + ":3:10: devices.eye.source: " + c.expected), std::string::npos)
        << c.source << ":\n" << run.output;
  }
}

TEST(FiducialCheck, AnExistingSourcePasses) {
  const fs::path dir = fresh_dir("present");
  fs::create_directories(dir / "frames");
  std::ofstream(dir / "frames" / "frame_0001.png") << "the check opens the file; decoding is the driver's";
  const CheckRun run = check(dir, "frames/frame_%04d.png");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find(": OK, 1 device(s)"), std::string::npos) << run.output;
}

// A camera is hardware: like a serial port, --check does not open it.
TEST(FiducialCheck, AnAbsentCameraPasses) {
  const fs::path dir = fresh_dir("camera");
  const CheckRun run = check(dir, "63");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find(": OK, 1 device(s)"), std::string::npos) << run.output;
}

TEST(FiducialCheck, AMissingCalibrationIsReportedAtItsKey) {
  const fs::path dir = fresh_dir("calibration");
  fs::create_directories(dir / "frames");
  std::ofstream(dir / "frames" / "frame_0001.png") << "x";
  const fs::path config = dir / "check.toml";
  std::ofstream(config) << "[devices.eye]\ntype = \"fiducial\"\nsource = \"frames/frame_%04d.png\"\n"
                           "calibration = \"nowhere.yml\"\n[[devices.eye.tags]]\nid = 0\nsize_m = 0.16\n";
  const CheckRun run = check_file(config.string());
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find(config.string() + ":4:15: devices.eye.calibration: "), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("nowhere.yml"), std::string::npos) << run.output;
}

// Loading a config to start from it does not open sources (their drivers do, and retry).
TEST(FiducialCheck, AStartDoesNotRequireTheSourceYet) {
  const std::string text = "[devices.eye]\ntype = \"fiducial\"\nsource = \"/nonexistent/frame_%04d.png\"\n"
                           "calibration = \"c.yml\"\n[[devices.eye.tags]]\nid = 0\nsize_m = 0.16\n";
  auto start = covtrack::server::parse_config(text, "start.toml");
  EXPECT_TRUE(start.has_value()) << start.error().message;
  auto checked = covtrack::server::parse_config(text, "start.toml", covtrack::server::ResourceChecks::Run);
  ASSERT_FALSE(checked.has_value());
  EXPECT_NE(checked.error().message.find("start.toml:3:10: devices.eye.source: image sequence "
                                         "'/nonexistent/frame_%04d.png': folder '/nonexistent' does not exist"),
            std::string::npos)
      << checked.error().message;
}

// The shipped bundle example, on the frames the build renders for it.
TEST(FiducialCheck, TheShippedBundleExampleIsAccepted) {
  const CheckRun run = check_file(COVTRACK_SOURCE_DIR "/config/fiducial_bundle.toml");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("fiducial_bundle.toml: OK, 1 device(s)"), std::string::npos) << run.output;
}
