// The VRPN parts of a config: the vrpn driver's keys and the [vrpn_server] section, each
// problem with file:line:column and key, both streams named when a tracker mixes frames.
#include <gtest/gtest.h>

#include <string>

#include "config.hpp"
#include "support/expect_has.hpp"

using covtrack::server::parse_config;
using covtrack::testing::expect_has;

namespace {

const std::string kDevices = R"(
[devices.optical]
type = "sim"
sensors = ["head", "wand"]
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]

[devices.magnetic]
type = "sim"
parent_frame = "magnetic_source"
sensor_count = 1
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)";

std::string errors_of(const std::string& text) {
  auto r = parse_config(text, "bad.toml");
  EXPECT_FALSE(r) << "config unexpectedly valid:\n" << text;
  return r ? std::string() : r.error().message;
}

}  // namespace

TEST(VrpnConfig, ShippedConfigsAreValid) {
  for (const char* name : {"vrpn_server.toml", "vrpn_relay.toml"}) {
    auto r = covtrack::server::load_config(std::string(COVTRACK_SOURCE_DIR "/config/") + name);
    ASSERT_TRUE(r) << name << ": " << r.error().message;
  }
  auto server = covtrack::server::load_config(COVTRACK_SOURCE_DIR "/config/vrpn_server.toml");
  ASSERT_TRUE(server->vrpn_server);
  ASSERT_EQ(server->vrpn_server->trackers.size(), 1u);
  EXPECT_EQ(server->vrpn_server->trackers[0].frame, "world");
  EXPECT_EQ(server->vrpn_server->port, 3883);
}

TEST(VrpnConfig, ATrackerMixingFramesNamesBothStreamsAndTheirFrames) {
  const auto msg = errors_of(kDevices + R"(
[vrpn_server]
[[vrpn_server.trackers]]
name = "Tracker0"
streams = ["optical/head", "magnetic/s0"]
)");
  expect_has(msg, "bad.toml:18:11: vrpn_server.trackers[0].streams:");
  expect_has(msg, "'optical/head' (frame 'world') and 'magnetic/s0' (frame 'magnetic_source')");
}

TEST(VrpnConfig, EachFrameInItsOwnTrackerIsValid) {
  auto r = parse_config(kDevices + R"(
[vrpn_server]
port = 3884
[[vrpn_server.trackers]]
name = "Optical"
streams = ["optical/head", "optical/wand"]
[[vrpn_server.trackers]]
name = "Magnetic"
streams = ["magnetic/s0"]
)",
                        "good.toml");
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->vrpn_server->trackers.size(), 2u);
  EXPECT_EQ(r->vrpn_server->trackers[1].frame, "magnetic_source");
  EXPECT_EQ(r->vrpn_server->trackers[0].streams[1], "optical/wand");
}

TEST(VrpnConfig, ServerMistakesEachGetTheirLine) {
  const auto msg = errors_of(kDevices + R"(
[vrpn_server]
address = "localhost"
port = 0
[[vrpn_server.trackers]]
name = "Tracker 0"
streams = ["optical/head", "optical/head", "nodevice/x", "head"]
[[vrpn_server.trackers]]
name = "Tracker 0"
streams = []
)");
  expect_has(msg, "bad.toml:16:11: vrpn_server.address: 'localhost' is no IPv4 address");
  expect_has(msg, "bad.toml:17:8: vrpn_server.port: 0 is out of range");
  expect_has(msg, "bad.toml:19:8: vrpn_server.trackers[0].name: 'Tracker 0' is no VRPN device name");
  expect_has(msg, "vrpn_server.trackers[0].streams: 'optical/head' is listed twice");
  expect_has(msg, "vrpn_server.trackers[0].streams: 'nodevice/x': no enabled device 'nodevice'");
  expect_has(msg, "vrpn_server.trackers[0].streams: 'head' is no stream: write \"device/sensor\"");
  expect_has(msg, "vrpn_server.trackers[1].name: tracker 'Tracker 0' is served twice");
  expect_has(msg, "bad.toml:23:11: vrpn_server.trackers[1].streams: lists no stream");
}

TEST(VrpnConfig, DriverMistakesEachGetTheirLine) {
  const auto msg = errors_of(R"(
[devices.relay]
type = "vrpn"
tracker = "Tracker0@host:99999"
silence_timeout_s = 0.1

[[devices.relay.sensors]]
number = 0
name = "head"

[[devices.relay.sensors]]
number = 0
name = "head"
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)");
  expect_has(msg, "bad.toml:4:11: devices.relay.tracker: 'Tracker0@host:99999': the port after ':' must be 1-65535");
  expect_has(msg, "bad.toml:5:21: devices.relay.silence_timeout_s: 0.1 is out of range");
  expect_has(msg, "bad.toml:8:10: devices.relay.sensors[0].number: no covariance: give sigma_m and sigma_rad");
  expect_has(msg, "devices.relay.sensors[1].number: sensor 0 is listed twice");
  expect_has(msg, "devices.relay.sensors[1].name: sensor name 'head' is used twice");
}

TEST(VrpnConfig, ADeviceCovarianceIsTheDefaultOfEverySensor) {
  auto r = parse_config(R"(
[devices.relay]
type = "vrpn"
tracker = "Tracker0@127.0.0.1"
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)",
                        "good.toml");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_FALSE(parse_config(R"(
[devices.relay]
type = "vrpn"
tracker = "Tracker0@127.0.0.1"
)",
                            "bad.toml"))
      << "with no sensor listed, the device needs a covariance";
}
