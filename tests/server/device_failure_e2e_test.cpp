// A device that cannot start (a missing video, a serial port path that is a regular file
// or not a terminal: config typos) fails with a clear error naming it, is restarted with
// back-off, and the daemon's other devices keep publishing; the daemon never aborts (a
// separate covtrackd process, inside a private network namespace).
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <chrono>
#include <fstream>
#include <ostream>
#include <map>

#include <lcm/lcm-cpp.hpp>

#include <covtrack/device_status_t.hpp>
#include <covtrack/pose_cov_t.hpp>

#include "daemon_process.hpp"

using namespace covtrack;

namespace {

class Collector {
 public:
  explicit Collector(const std::string& url) : lcm_(url) {
    lcm_.subscribe("covtrack/pose/.*", &Collector::on_pose, this)->setQueueCapacity(100000);
    lcm_.subscribe("covtrack/status/.*", &Collector::on_status, this)->setQueueCapacity(1000);
  }
  void run_for(double seconds) {
    covtrack::test::handle_for(lcm_, seconds);
  }
  std::map<std::string, int> poses;
  std::map<std::string, device_status_t> status;

 private:
  void on_pose(const lcm::ReceiveBuffer*, const std::string& ch, const pose_cov_t*) { ++poses[ch]; }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const device_status_t* m) {
    status[m->device] = *m;
  }
  lcm::LCM lcm_;
};

}  // namespace

struct BadDevice {
  std::string name;
  std::string config;    // one [devices.bad] table
  std::string expected;  // in the device's last_error
};

void PrintTo(const BadDevice& d, std::ostream* os) { *os << d.name; }

class DeviceFailureE2e : public ::testing::TestWithParam<BadDevice> {};

TEST_P(DeviceFailureE2e, IsReportedAndOtherDevicesGoOn) {
  const std::string url = "udpm://239.255.76.67:7741?ttl=0";
  const std::string config = R"(
[daemon]
heartbeat_hz = 5.0

[devices.steady]
type = "sim"
sensor_count = 1
rate_hz = 50
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)" + GetParam().config;
  Collector collector(url);
  test::DaemonProcess daemon(config, url);
  // 3 s at least, and until the bad device has been restarted and the sim device has
  // published 50 poses (1 s at its rate): a loaded machine only makes the wait longer.
  collector.run_for(3.0);
  const auto restarted = [&] { return collector.status.count("bad") && collector.status["bad"].restarts >= 1; };
  for (int waited = 0; waited < 60 && !(restarted() && collector.poses["covtrack/pose/steady/s0"] > 50); ++waited)
    collector.run_for(0.5);
  EXPECT_GT(collector.poses["covtrack/pose/steady/s0"], 50) << "the sim device must keep publishing";
  ASSERT_TRUE(collector.status.count("bad"));
  const device_status_t& bad = collector.status["bad"];
  EXPECT_NE(bad.last_error.find(GetParam().expected), std::string::npos) << bad.last_error;
  EXPECT_GE(bad.restarts, 1);
  int status = 0;
  EXPECT_GE(daemon.stop(SIGTERM, status), 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the daemon must stop cleanly, status " << status;
}

std::string plain_file() {
  const std::string path = ::testing::TempDir() + "/covtrack_not_a_port";
  std::ofstream(path) << "not a serial port\n";
  return path;
}

INSTANTIATE_TEST_SUITE_P(
    Devices, DeviceFailureE2e,
    ::testing::Values(
        BadDevice{"missing_video", R"(
[devices.bad]
type = "fiducial"
source = "/nonexistent/covtrack/video.avi"
calibration = ")" COVTRACK_SOURCE_DIR R"(/config/cameras/rendered_640x480.yml"

[[devices.bad.tags]]
id = 0
size_m = 0.1
)",
                  "video file '/nonexistent/covtrack/video.avi' does not exist"},
        BadDevice{"fastrak_port_is_a_file", R"(
[devices.bad]
type = "fastrak"
port = ")" + plain_file() + R"("
reset_time_s = 1

[[devices.bad.stations]]
number = 1
name = "head"
)",
                  "is a regular file, not a serial device"},
        BadDevice{"flock_port_is_dev_null", R"(
[devices.bad]
type = "flock"
port = "/dev/null"
reset_time_s = 1

[[devices.bad.stations]]
number = 1
name = "head"
)",
                  "cannot be set up as a terminal"}),
    [](const ::testing::TestParamInfo<BadDevice>& info) { return info.param.name; });
