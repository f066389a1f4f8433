// covtrackd given a bad config: exit code 2, the problem on stderr with its file and
// line, and nothing started. (How each kind of problem is worded: config_test.)
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <string>

namespace {

TEST(DaemonBadConfig, ExitsWithCode2AndStartsNothing) {
  const std::string path = ::testing::TempDir() + "/covtrack_bad.toml";
  std::ofstream(path) << "[devices.opt]\ntype = \"sim\"\nsensors = [\"head\"]\nrate_hz = 0\n";
  const std::string cmd = std::string(COVTRACK_BINARY_DIR "/server/covtrackd --config ") + path +
                          " --lcm-url memq:// 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) out += buf;
  const int status = pclose(p);
  ASSERT_TRUE(WIFEXITED(status)) << out;
  EXPECT_EQ(WEXITSTATUS(status), 2) << out;
  EXPECT_NE(out.find(path + ":4:11: devices.opt.rate_hz:"), std::string::npos) << out;
  EXPECT_EQ(out.find("publishing"), std::string::npos) << out;
}

}  // namespace
