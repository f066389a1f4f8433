// covtrackd given a bad config: exit code 2, the problem on stderr with its file and
// line, and nothing started. (How each kind of problem is worded: config_test.)
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "support/run_command.hpp"

namespace {

TEST(DaemonBadConfig, ExitsWithCode2AndStartsNothing) {
  const std::string path = ::testing::TempDir() + "/covtrack_bad.toml";
  std::ofstream(path) << "[devices.opt]\ntype = \"sim\"\nsensors = [\"head\"]\nrate_hz = 0\n";
  // exit_code is -1 unless the daemon exited normally, so 2 also says it did.
  const auto run = covtrack::testing::run_command(std::string(COVTRACK_BINARY_DIR "/server/covtrackd --config ") +
                                                  path + " --lcm-url memq://");
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find(path + ":4:11: devices.opt.rate_hz:"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("publishing"), std::string::npos) << run.out;
}

}  // namespace
