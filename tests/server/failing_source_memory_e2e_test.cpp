// A source that cannot be opened has its driver restarted again and again (a camera left
// unplugged for days), and every restart must give back what it took. A real covtrackd
// whose fiducial source is a file that is no video restarts the driver every 10 ms
// (daemon.restart_backoff_*_s); between the 20th failure (after which libraries have
// made their one-time allocations) and the 220th, its resident memory (VmRSS) must grow
// by less than 1 MB. With OpenCV's automatic backend choice each failed open leaked
// about 26 KB inside libgphoto2/libusb: over 5 MB across these 200.
// Inside a private network namespace (the heartbeats count the restarts).
#include <gtest/gtest.h>

#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>

#include <covtrack/device_status_t.hpp>

#include "daemon_process.hpp"

using namespace covtrack;

namespace {

// Resident memory of a process in KiB, from /proc/<pid>/status; -1 if not found.
long resident_kib(pid_t pid) {
  std::ifstream status(fmt::format("/proc/{}/status", pid));
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

// Follows one device's heartbeats.
class Restarts {
 public:
  Restarts(const std::string& url, const std::string& device) : lcm_(url) {
    lcm_.subscribe("covtrack/status/" + device, &Restarts::on_status, this);
  }
  // Handles heartbeats until one counts at least `count` restarts (true) or 60 s passed.
  bool until(std::int64_t count) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    pollfd pfd{lcm_.getFileno(), POLLIN, 0};
    while (std::chrono::steady_clock::now() < end) {
      if (last_ && last_->restarts >= count) return true;
      if (poll(&pfd, 1, 20) > 0) lcm_.handle();
    }
    return false;
  }
  const std::optional<device_status_t>& last() const { return last_; }

 private:
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const device_status_t* m) { last_ = *m; }
  lcm::LCM lcm_;
  std::optional<device_status_t> last_;
};

}  // namespace

TEST(FailingSourceMemory, StaysFlatOver200FailedOpens) {
  const std::string video = fmt::format("{}/covtrack_not_a_video_{}.avi", ::testing::TempDir(), ::getpid());
  std::ofstream(video) << "RIFF, but no video in it\n";
  const std::string url = "udpm://239.255.76.67:7752?ttl=0";
  const std::string config = fmt::format(R"(
[daemon]
heartbeat_hz = 50
restart_backoff_initial_s = 0.01
restart_backoff_max_s = 0.01

[devices.cam]
type = "fiducial"
source = "{}"
calibration = "{}/config/cameras/rendered_640x480.yml"

[[devices.cam.tags]]
id = 0
size_m = 0.1
)",
                                         video, COVTRACK_SOURCE_DIR);
  Restarts restarts(url, "cam");
  test::DaemonProcess daemon(config, url);
  ASSERT_TRUE(restarts.until(20)) << "the device never failed 20 times";
  const auto first = restarts.last()->restarts;
  const long before_kib = resident_kib(daemon.pid());
  ASSERT_TRUE(restarts.until(first + 200)) << "200 more failures did not come within 60 s";
  const long after_kib = resident_kib(daemon.pid());
  const auto& last = *restarts.last();
  std::printf("VmRSS %ld KiB after %lld failed opens, %ld KiB after %lld: %+ld KiB; last error: %s\n", before_kib,
              static_cast<long long>(first), after_kib, static_cast<long long>(last.restarts),
              after_kib - before_kib, last.last_error.c_str());
  ASSERT_GT(before_kib, 0);
  EXPECT_NE(last.last_error.find("not a video OpenCV can read"), std::string::npos) << last.last_error;
  EXPECT_LT(after_kib - before_kib, 1024) << "the daemon grows with every failed open";
  int exit_status = 0;
  EXPECT_GE(daemon.stop(SIGTERM, exit_status), 0);
  std::remove(video.c_str());
}
