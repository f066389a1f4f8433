// The command-line conventions of both programs, run as a user runs them: --version, the
// exit codes (0 ok, 1 runtime error, 2 usage or config error, 3 damaged input), one-line
// usage errors, short flags and choice names in --help. LCM stays in the process (memq://).
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "cli_support.hpp"

using covtrack::testing::CliRun;
using covtrack::testing::run_command;
using covtrack::testing::run_covtrack;
namespace fs = std::filesystem;

namespace {

const std::string kDaemon = COVTRACKD;
const std::string kScene = COVTRACK_SOURCE_DIR "/config/scenes/head_and_world.toml";

CliRun daemon(const std::string& args) { return run_command(kDaemon + " " + args); }

class CliConventions : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("covtrack_cli_conventions_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(CliConventions, BothProgramsPrintTheProjectVersion) {
  const CliRun cli = run_covtrack("--version");
  EXPECT_EQ(cli.exit_code, 0);
  EXPECT_EQ(cli.out, "covtrack " COVTRACK_PROJECT_VERSION "\n");
  const CliRun d = daemon("--version");
  EXPECT_EQ(d.exit_code, 0);
  EXPECT_EQ(d.out, "covtrackd " COVTRACK_PROJECT_VERSION "\n");
}

TEST_F(CliConventions, UsageErrorsAreOneLineAndExit2) {
  const struct {
    std::string args, out;
  } cases[] = {
      {"foo", "covtrack: unknown command 'foo' (try covtrack --help)\n"},
      {"", "covtrack: a command is required (try covtrack --help)\n"},
      {"echo --count -1", "covtrack echo: --count: must be 0 or more, got -1 (try covtrack echo --help)\n"},
      {"record x.lcm -d 0", "covtrack record: --duration: must be more than 0, got 0 (try covtrack record --help)\n"},
      {"echo --bogus", "covtrack echo: The following argument was not expected: --bogus (try covtrack echo --help)\n"},
      // the subcommands that run in covtrack-vision say the same
      {"view " + kScene + " --confidence 2",
       "covtrack view: --confidence: must be between 0.5 and 0.9999, got 2 (try covtrack view --help)\n"},
      {"regions " + kScene + " --method cubic",
       "covtrack regions: --method: must be one of linear, unscented, got cubic (try covtrack regions --help)\n"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_covtrack(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.out;
    EXPECT_EQ(r.out, c.out) << c.args;
  }
  const CliRun d = daemon("--bogus");
  EXPECT_EQ(d.exit_code, 2) << d.out;
  EXPECT_EQ(d.out, "covtrackd: The following argument was not expected: --bogus (try covtrackd --help)\n");
}

TEST_F(CliConventions, HelpListsExitCodesShortFlagsAndChoiceNames) {
  for (const std::string args : {"--help", "echo --help", "replay --help", "view --help", "regions --help"}) {
    const CliRun r = run_covtrack(args);
    EXPECT_EQ(r.exit_code, 0) << args;
    EXPECT_NE(r.out.find("Exit codes: 0 ok; 1 runtime error; 2 usage or config error; 3 damaged input"),
              std::string::npos)
        << args << "\n" << r.out;
  }
  const std::string echo = run_covtrack("echo --help").out;
  for (const char* flag : {"-n,--count", "-d,--duration", "-j,--json", "-u,--lcm-url"})
    EXPECT_NE(echo.find(flag), std::string::npos) << flag << "\n" << echo;
  EXPECT_NE(run_covtrack("replay --help").out.find("-s,--speed"), std::string::npos);
  const std::string regions = run_covtrack("regions --help").out;
  EXPECT_NE(regions.find("{linear, unscented}"), std::string::npos) << regions;
  EXPECT_NE(regions.find("{lca, osgar-matrix16, osgar-root}"), std::string::npos) << regions;
  EXPECT_EQ(regions.find("->"), std::string::npos) << "enum values in the help:\n" << regions;
  const CliRun d = daemon("--help");
  EXPECT_EQ(d.exit_code, 0);
  EXPECT_NE(d.out.find("4 covtrackd only"), std::string::npos) << d.out;
  EXPECT_NE(d.out.find("-c,--config"), std::string::npos) << d.out;
}

TEST_F(CliConventions, BadConfigExits2) {
  const fs::path broken = dir_ / "broken.toml";
  std::ofstream(broken) << "[daemon\nlcm_url = \"memq://\"\n";
  for (const std::string args : {"--check --config " + broken.string(), "--config " + broken.string(),
                                 "--config " + (dir_ / "missing.toml").string()}) {
    const CliRun r = daemon(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(dir_.string()), std::string::npos) << r.out;  // names the file
  }
}

// The recorded Lenz session cut in the middle of an event: replay publishes what is whole
// and says where the damage is.
TEST_F(CliConventions, DamagedLogExits3) {
  const fs::path truncated = dir_ / "truncated.lcm";
  fs::copy_file(COVTRACK_SOURCE_DIR "/tests/data/lenz_session.lcm", truncated);
  fs::resize_file(truncated, fs::file_size(truncated) / 2 + 7);
  const CliRun r = run_covtrack("replay " + truncated.string() + " -s 0 -u memq://");
  EXPECT_EQ(r.exit_code, 3) << r.out;
  EXPECT_NE(r.out.find("damaged"), std::string::npos) << r.out;
}

TEST_F(CliConventions, RuntimeErrorsExit1) {
  const CliRun record = run_covtrack("record " + (dir_ / "no/such/folder/x.lcm").string() + " -u memq://");
  EXPECT_EQ(record.exit_code, 1) << record.out;
  EXPECT_NE(record.out.find("no/such/folder/x.lcm"), std::string::npos) << record.out;
  const CliRun camera =
      run_covtrack("view " + kScene + " --png " + (dir_ / "x.png").string() + " --background camera:57");
  EXPECT_EQ(camera.exit_code, 1) << camera.out;
  EXPECT_NE(camera.out.find("camera:57"), std::string::npos) << camera.out;
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));
}

}  // namespace
