// A source that cannot be opened has its driver restarted again and again (a camera left
// unplugged for days), and every restart must give back what it took. A real covtrackd
// whose fiducial source is a file that is no video restarts the driver every 10 ms
// (daemon.restart_backoff_*_s); between the 20th failure (after which libraries have
// made their one-time allocations) and the 220th, its resident memory (VmRSS) must grow
// by less than 1 MB. With OpenCV's automatic backend choice each failed open left
// memory behind inside libgphoto2/libusb: 33 MB across these 200 when measured.
// Inside a private network namespace (the heartbeats count the restarts).
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include <fmt/format.h>

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
  test::StatusWatch watch(url, "cam");
  test::DaemonProcess daemon(config, url);
  const auto restarted = [](std::int64_t count) {
    return [count](const device_status_t& s) { return s.restarts >= count; };
  };
  const auto warm = watch.until(restarted(20), 60);
  ASSERT_TRUE(warm && warm->restarts >= 20) << "the device never failed 20 times";
  const std::int64_t first = warm->restarts;
  const long before_kib = resident_kib(daemon.pid());
  const auto later = watch.until(restarted(first + 200), 60);
  ASSERT_TRUE(later && later->restarts >= first + 200) << "200 more failures did not come within 60 s";
  const long after_kib = resident_kib(daemon.pid());
  const device_status_t& last = *later;
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
