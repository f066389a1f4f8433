// Every kind of bad config gives its own error with file:line:column and the key path,
// all of them at once, and nothing starts.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "config.hpp"
#include "support/expect_has.hpp"

using covtrack::server::parse_config;
using covtrack::testing::expect_has;

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

// Found by mutation fuzzing (tests/server/config_mutation_fuzz.py): a config repeating a
// serial station, VRPN sensor, served tracker or tag bundle thousands of times got one
// error per pair of repeats (3,000 stations: 4.5 million errors, 3.8 GB, a minute). Now
// each repeat is one error.
TEST(Config, EachRepeatedTableIsOneError) {
  const auto repeated = [](const std::string& head, const std::string& table, int times) {
    std::string text = head;
    for (int i = 0; i < times; ++i) text += table;
    return text;
  };
  struct Case {
    std::string text, error;
  };
  const std::string frames = COVTRACK_SOURCE_DIR "/config/cameras/rendered_640x480.yml";
  const std::vector<Case> cases = {
      {repeated("[devices.f]\ntype = \"fastrak\"\nport = \"/dev/null\"\n",
                "[[devices.f.stations]]\nnumber = 1\nname = \"a\"\n", 4),
       "station 1 is listed twice"},
      {repeated("[devices.v]\ntype = \"vrpn\"\ntracker = \"T@localhost\"\nsigma_m = [0.001, 0.001, 0.001]\n"
                "sigma_rad = [0.001, 0.001, 0.001]\n",
                "[[devices.v.sensors]]\nnumber = 0\nname = \"a\"\n", 4),
       "sensor 0 is listed twice"},
      {repeated(std::string(kGoodDevice) + "[vrpn_server]\n",
                "[[vrpn_server.trackers]]\nname = \"T\"\nstreams = [\"opt/head\"]\n", 4),
       "tracker 'T' is served twice"},
      {repeated("[devices.d]\ntype = \"fiducial\"\nsource = \"0\"\ncalibration = \"" + frames + "\"\n",
                "[[devices.d.bundles]]\nname = \"b\"\n[[devices.d.bundles.tags]]\nid = 1\nsize_m = 0.1\n", 4),
       "bundle 'b' is named twice"},
  };
  for (const Case& c : cases) {
    auto r = parse_config(c.text, "repeats.toml");
    ASSERT_FALSE(r) << c.text;
    const std::string& m = r.error().message;
    std::size_t count = 0;
    for (auto at = m.find(c.error); at != std::string::npos; at = m.find(c.error, at + 1)) ++count;
    EXPECT_EQ(count, 3u) << "three repeats of the first, one error each:\n" << m;
  }
}

// A sim device lists at most 64 sensors, each once (as sensor_count allows): 100,000
// names (found by mutation fuzzing) made a device that did not stop in time.
TEST(Config, SimSensorsAreAtMost64AndDistinct) {
  std::string many = "[devices.s]\ntype = \"sim\"\nsigma_m = [0.001, 0.001, 0.001]\nsigma_rad = [0.001, 0.001, 0.001]\n"
                     "sensors = [";
  for (int i = 0; i < 65; ++i) many += "\"s" + std::to_string(i) + "\", ";
  expect_has(only_error(many + "]\n"), "bad.toml:5:11: devices.s.sensors: 65 sensors: at most 64");
  const std::string twice = "[devices.s]\ntype = \"sim\"\nsigma_m = [0.001, 0.001, 0.001]\n"
                            "sigma_rad = [0.001, 0.001, 0.001]\nsensors = [\"a\", \"b\", \"a\"]\n";
  expect_has(only_error(twice), "bad.toml:5:11: devices.s.sensors: 'a' is listed twice");
}

// However many problems a config has, the report shows the first 100 and says so.
TEST(Config, AtMost100ProblemsAreShown) {
  std::string text = kGoodDevice;
  for (int i = 0; i < 500; ++i) text += "bogus_" + std::to_string(i) + " = 1\n";
  auto r = parse_config(text, "many.toml");
  ASSERT_FALSE(r);
  const std::string& m = r.error().message;
  EXPECT_EQ(std::count(m.begin(), m.end(), '\n'), 101) << m.substr(0, 2000);
  expect_has(m, ": unknown key");
  expect_has(m, "(only the first 100 problems are shown)\n");
}

// A config (or a track layout) is read to at most 4 MiB: a bigger file, or a pipe fed
// without end, is refused instead of taking the daemon's memory.
TEST(Config, AFileOrPipeOver4MiBIsRefused) {
  const std::string big = ::testing::TempDir() + "/covtrack_big_config.toml";
  {
    std::ofstream out(big);
    out << kGoodDevice;
    const std::string comment = "# " + std::string(1000, 'x') + "\n";
    for (int i = 0; i < 4200; ++i) out << comment;
  }
  auto r = covtrack::server::load_config(big);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, big + ": is larger than 4 MiB, too large for a config file");

  const std::string fifo = ::testing::TempDir() + "/covtrack_endless_config_" + std::to_string(getpid());
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::signal(SIGPIPE, SIG_IGN);  // the writer sees EPIPE when the reader gives up
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    const std::string line = "# endless\n";
    while (fd >= 0 && ::write(fd, line.data(), line.size()) > 0) {
    }
    if (fd >= 0) ::close(fd);
  });
  auto endless = covtrack::server::load_config(fifo);
  writer.join();
  ::unlink(fifo.c_str());
  ASSERT_FALSE(endless);
  EXPECT_EQ(endless.error().message, fifo + ": is larger than 4 MiB, too large for a config file");
}

TEST(Config, SchemaDocumentIsUpToDate) {
  std::ifstream in(COVTRACK_SOURCE_DIR "/config/schema.md");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), covtrack::server::config_schema_markdown())
      << "regenerate it: covtrackd --print-schema > config/schema.md";
}

// [auth]: the key is read with the config, relative to it; a key file others can read,
// or a missing one, is an error at its key, and nothing starts.
TEST(Config, AuthKeyFileIsReadRelativeToTheConfigAndMustBeSecret) {
  const std::string dir = ::testing::TempDir() + "/config_auth_" + std::to_string(::getpid());
  ::mkdir(dir.c_str(), 0700);
  const std::string key = dir + "/lab.key";
  ::unlink(key.c_str());
  ASSERT_TRUE(covtrack::write_new_auth_key(key));
  const std::string config = dir + "/daemon.toml";
  const std::string text = std::string(kGoodDevice) + "\n[auth]\nkey_file = \"lab.key\"\n";
  auto good = parse_config(text, config);
  ASSERT_TRUE(good) << good.error().message;
  ASSERT_TRUE(good->auth_key);
  EXPECT_EQ(good->auth_key->bytes, covtrack::load_auth_key(key)->bytes);
  EXPECT_FALSE(parse_config(kGoodDevice, config)->auth_key) << "off by default";

  ::chmod(key.c_str(), 0604);
  auto readable = parse_config(text, config);
  ASSERT_FALSE(readable);
  EXPECT_NE(readable.error().message.find(config + ":9:12: auth.key_file: key file " + key + ": others may read"),
            std::string::npos)
      << readable.error().message;
  auto missing = parse_config(std::string(kGoodDevice) + "\n[auth]\nkey_file = \"absent.key\"\n", config);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("auth.key_file: key file " + dir + "/absent.key: No such file"),
            std::string::npos)
      << missing.error().message;
}
