// Every kind of bad config gives its own error with file:line:column and the key path,
// all of them at once, and nothing starts.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "config.hpp"

using covtrack::server::parse_config;

namespace {

const char* kGoodDevice = R"(
[devices.opt]
type = "sim"
sensors = ["head"]
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)";

// The single error a config produces (fails the test if there is not exactly one).
std::string only_error(const std::string& text) {
  auto r = parse_config(text, "bad.toml");
  EXPECT_FALSE(r) << "config unexpectedly valid:\n" << text;
  if (r) return {};
  std::string msg = r.error().message;
  EXPECT_EQ(std::count(msg.begin(), msg.end(), '\n'), 1) << msg;
  return msg;
}

void expect_has(const std::string& msg, const std::string& part) {
  EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
}

}  // namespace

TEST(Config, ShippedExampleIsValid) {
  auto r = covtrack::server::load_config(COVTRACK_SOURCE_DIR "/config/sim.toml");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->devices.size(), 2u);
}

TEST(Config, UnknownKeyNamesTheKeyAndItsLine) {
  const auto msg = only_error(std::string(kGoodDevice) + "rate_hzz = 10\n");
  expect_has(msg, "bad.toml:7:1: devices.opt.rate_hzz: unknown key");
  expect_has(msg, "rate_hz");  // the known keys are listed
}

TEST(Config, WrongType) {
  const auto msg = only_error(std::string(kGoodDevice) + "rate_hz = \"fast\"\n");
  expect_has(msg, "bad.toml:7:");
  expect_has(msg, "devices.opt.rate_hz: expected number, found string");
}

TEST(Config, MissingRequiredKey) {
  const auto msg = only_error(R"(
[devices.opt]
type = "sim"
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)");
  expect_has(msg, "bad.toml:2:");
  expect_has(msg, "devices.opt.sensors");
}

TEST(Config, OutOfRange) {
  const auto msg = only_error(std::string(kGoodDevice) + "rate_hz = -5\n");
  expect_has(msg, "bad.toml:7:");
  expect_has(msg, "devices.opt.rate_hz: -5 is out of range");
}

TEST(Config, ArrayItemOutOfRangeAndWrongLength) {
  auto msg = only_error(R"(
[devices.opt]
type = "sim"
sensors = ["head"]
sigma_m = [0.001, -1, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)");
  expect_has(msg, "bad.toml:5:");
  expect_has(msg, "devices.opt.sigma_m[1]");
  msg = only_error(R"(
[devices.opt]
type = "sim"
sensors = ["head"]
sigma_m = [0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)");
  expect_has(msg, "expected 3 numbers, found 2");
}

TEST(Config, UnknownDriverTypeListsTheKnownOnes) {
  const auto msg = only_error("[devices.x]\ntype = \"vicon\"\n");
  // Every driver row adds a name: check the start of the list and that others follow.
  expect_has(msg, "bad.toml:2:8: devices.x.type: unknown driver type 'vicon' (known: sim, ");
}

TEST(Config, BadDeviceNameAndBadSensorName) {
  expect_has(only_error(std::string(kGoodDevice) + "[devices.\"has space\"]\ntype = \"sim\"\n"),
             "devices.has space: device name must be");
  expect_has(only_error(R"(
[devices.opt]
type = "sim"
sensors = ["head/left"]
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)"), "'head/left' is not a valid sensor name");
}

TEST(Config, ParentFrameWithAControlCharacterIsRefused) {
  // Clients reject such a pose on the wire; the daemon says so before it starts.
  expect_has(only_error(std::string(kGoodDevice) + "parent_frame = \"world\\u001b[2J\"\n"),
             "bad.toml:7:16: devices.opt.parent_frame: must hold no control character");
  EXPECT_TRUE(parse_config(std::string(kGoodDevice) + "parent_frame = \"Welt \u00e9\"\n", "good.toml"));
}

TEST(Config, NestedTableKeyPath) {
  const auto msg = only_error(std::string(kGoodDevice) + "[devices.opt.motion]\nkind = \"spiral\"\n");
  expect_has(msg, "bad.toml:8:");
  expect_has(msg, "devices.opt.motion.kind: 'spiral' is not one of");
}

TEST(Config, SyntaxErrorHasPosition) {
  auto r = parse_config("[devices.opt\ntype = 1\n", "bad.toml");
  ASSERT_FALSE(r);
  expect_has(r.error().message, "bad.toml:1:");
  expect_has(r.error().message, "TOML syntax error");
}

TEST(Config, NoDevicesAndDaemonSettings) {
  expect_has(only_error("[daemon]\nheartbeat_hz = 1\n"), "devices: missing required key");
  expect_has(only_error(std::string("[daemon]\nheartbeat_hz = 0\n") + kGoodDevice),
             "bad.toml:2:16: daemon.heartbeat_hz: 0 is out of range");
}

TEST(Config, AllErrorsAreReportedTogether) {
  auto r = parse_config(std::string(kGoodDevice) + "rate_hz = -1\nbogus = 1\n[devices.y]\ntype = \"nope\"\n",
                        "bad.toml");
  ASSERT_FALSE(r);
  const std::string& m = r.error().message;
  EXPECT_EQ(std::count(m.begin(), m.end(), '\n'), 3) << m;
}

TEST(Config, DisabledDeviceIsValidatedButNotStarted) {
  auto r = parse_config(std::string(kGoodDevice) + "enabled = false\n", "ok.toml");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_TRUE(r->devices.empty());
}

// A device node or a folder is no config: reading one could block or never end (a pipe
// is read; shutdown_e2e_test).
TEST(Config, ADeviceOrAFolderIsRefusedAsAConfig) {
  for (const std::string path : {"/dev/zero", "/tmp"}) {
    auto r = covtrack::server::load_config(path);
    ASSERT_FALSE(r) << path;
    EXPECT_NE(r.error().message.find(path + ": is a "), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(", not a file to read"), std::string::npos) << r.error().message;
  }
}

TEST(Config, SchemaDocumentIsUpToDate) {
  std::ifstream in(COVTRACK_SOURCE_DIR "/config/schema.md");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), covtrack::server::config_schema_markdown())
      << "regenerate it: covtrackd --print-schema > config/schema.md";
}

// The binary: exit code 2, the message on stderr, nothing started.
TEST(Config, DaemonExitsWithCode2AndStartsNothing) {
  const std::string path = ::testing::TempDir() + "/covtrack_bad.toml";
  std::ofstream(path) << kGoodDevice << "rate_hz = 0\n";
  const std::string cmd = std::string(COVTRACK_BINARY_DIR "/server/covtrackd --config ") + path +
                          " --lcm-url memq:// 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) out += buf;
  const int status = pclose(p);
  EXPECT_EQ(WEXITSTATUS(status), 2) << out;
  expect_has(out, path + ":7:");
  EXPECT_EQ(out.find("publishing"), std::string::npos) << out;
}
