// A camera that delivers frames but sees no tag: the daemon's heartbeat shows the device
// RUNNING with the detail "no tag in view" (before, it stayed STARTING for good, as no
// pose ever came). A separate covtrackd process on frames without tags, inside a private
// network namespace.
#include <gtest/gtest.h>

#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <random>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <covtrack/device_status_t.hpp>

#include "daemon_process.hpp"

using namespace covtrack;
namespace fs = std::filesystem;

namespace {

// Keeps the latest heartbeat of the device.
class StatusWatch {
 public:
  explicit StatusWatch(const std::string& url) : lcm_(url) {
    lcm_.subscribe("covtrack/status/eye", &StatusWatch::on_status, this);
  }
  // Handles messages until a heartbeat says RUNNING or 30 s passed; the last heartbeat.
  std::optional<device_status_t> until_running() {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    pollfd pfd{lcm_.getFileno(), POLLIN, 0};
    while (std::chrono::steady_clock::now() < end &&
           !(last_ && last_->state == device_status_t::STATE_RUNNING))
      if (poll(&pfd, 1, 20) > 0) lcm_.handle();
    return last_;
  }

 private:
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const device_status_t* m) { last_ = *m; }
  lcm::LCM lcm_;
  std::optional<device_status_t> last_;
};

}  // namespace

TEST(FiducialStatusE2e, FramesWithoutATagAreRunningWithNoTagInView) {
  const fs::path dir = fs::path(::testing::TempDir()) / fmt::format("fiducial_status_{}", getpid());
  fs::create_directories(dir);
  std::mt19937 rng(1);
  for (int i = 0; i < 3; ++i) {  // an empty grey room with sensor noise, 640x480
    cv::Mat frame(480, 640, CV_8UC1);
    cv::randn(frame, 120, 4);
    ASSERT_TRUE(cv::imwrite((dir / fmt::format("frame_{:04d}.png", i)).string(), frame));
  }
  const std::string url = "udpm://239.255.76.67:7744?ttl=0";
  const std::string config = fmt::format(R"(
[daemon]
heartbeat_hz = 10

[devices.eye]
type = "fiducial"
source = "{}/frame_%04d.png"
calibration = "{}/config/cameras/rendered_640x480.yml"
rate_hz = 30
loop = true

[[devices.eye.tags]]
id = 0
size_m = 0.16
)", dir.string(), COVTRACK_SOURCE_DIR);
  StatusWatch watch(url);
  test::DaemonProcess daemon(config, url);
  const auto status = watch.until_running();
  int exit_status = 0;
  EXPECT_GE(daemon.stop(SIGTERM, exit_status), 0);
  ASSERT_TRUE(status.has_value()) << "no heartbeat from the daemon";
  EXPECT_EQ(int{status->state}, int{device_status_t::STATE_RUNNING})
      << "state " << int{status->state} << ", last error: " << status->last_error;
  EXPECT_EQ(status->detail, "no tag in view");
  EXPECT_EQ(status->reports, 0);
  EXPECT_EQ(status->errors, 0) << status->last_error;
}
