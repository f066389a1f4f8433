// A fiducial device whose video is missing fails with a clear error, is restarted with
// back-off, and the daemon's other devices keep publishing (a separate covtrackd
// process, inside a private network namespace).
#include <gtest/gtest.h>


#include <chrono>
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

TEST(FiducialFailureE2e, MissingVideoIsReportedAndOtherDevicesGoOn) {
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

[devices.eye]
type = "fiducial"
source = "/nonexistent/covtrack/video.avi"
calibration = ")" COVTRACK_SOURCE_DIR R"(/config/cameras/rendered_640x480.yml"

[[devices.eye.tags]]
id = 0
size_m = 0.1
)";
  Collector collector(url);
  test::DaemonProcess daemon(config, url);
  collector.run_for(3.0);
  EXPECT_GT(collector.poses["covtrack/pose/steady/s0"], 50) << "the sim device must keep publishing";
  ASSERT_TRUE(collector.status.count("eye"));
  const device_status_t& eye = collector.status["eye"];
  EXPECT_NE(eye.last_error.find("cannot open video source '/nonexistent/covtrack/video.avi'"),
            std::string::npos) << eye.last_error;
  EXPECT_GE(eye.restarts, 1);
  int status = 0;
  EXPECT_GE(daemon.stop(SIGTERM, status), 0);
}
