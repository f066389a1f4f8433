// A stop that always completes, with a real covtrackd (inside a private network
// namespace):
// - a fiducial source that is a FIFO nobody writes to is refused for its kind, never
//   opened (an open would block the driver's thread and the daemon's stop): the device is
//   FAILED naming it, and SIGTERM stops the daemon at once with exit code 0;
// - a --config that is a FIFO nobody writes to: SIGTERM ends the daemon while it waits
//   (the signals are handled before the config is read), saying so;
// - a config that comes through a pipe is read, so `--config <(make-config)` works.
// The daemon's limit on a driver that never returns (exit code 4) is host_stop_test's.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include <covtrack/device_status_t.hpp>

#include "daemon_process.hpp"

using namespace covtrack;

namespace {

std::string temp_path(const std::string& name) {
  return fmt::format("{}/covtrack_shutdown_{}_{}", ::testing::TempDir(), name, ::getpid());
}

std::string make_fifo(const std::string& name) {
  const std::string path = temp_path(name);
  ::unlink(path.c_str());
  EXPECT_EQ(::mkfifo(path.c_str(), 0600), 0) << path;
  return path;
}

std::string text_of(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Opens the FIFO's writing end once a reader has opened the other (the daemon has begun
// to read it); -1 if none did within 10 s. Without a reader a non-blocking open fails
// with ENXIO, so this never blocks.
int writer_once_read(const std::string& fifo) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < end) {
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0 || errno != ENXIO) return fd;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return -1;
}

class FifoSource : public ::testing::TestWithParam<std::string> {};

}  // namespace

TEST_P(FifoSource, IsRefusedAndSigtermStopsTheDaemonAtOnce) {
  const std::string fifo = make_fifo("source_" + GetParam());
  const std::string url = "udpm://239.255.76.67:7751?ttl=0";
  const std::string config = fmt::format(R"(
[daemon]
heartbeat_hz = 10
restart_backoff_initial_s = 0.2

[devices.cam]
type = "fiducial"
source = "{}"
calibration = "{}/config/cameras/rendered_640x480.yml"

[[devices.cam.tags]]
id = 0
size_m = 0.1
)",
                                         fifo, COVTRACK_SOURCE_DIR);
  test::StatusWatch watch(url, "cam");
  test::DaemonProcess daemon(config, url);
  const auto status =
      watch.until([](const device_status_t& s) { return s.state == device_status_t::STATE_FAILED; }, 20);
  ASSERT_TRUE(status) << "no heartbeat from the device";
  EXPECT_EQ(int{status->state}, int{device_status_t::STATE_FAILED});
  EXPECT_NE(status->last_error.find(fifo + "' is a FIFO (named pipe), not a regular file"), std::string::npos)
      << status->last_error;
  int exit_status = 0;
  const double took_s = daemon.stop(SIGTERM, exit_status);
  ASSERT_GE(took_s, 0) << "covtrackd did not end within 5 s of SIGTERM";
  EXPECT_TRUE(WIFEXITED(exit_status) && WEXITSTATUS(exit_status) == 0) << "status " << exit_status;
  ::unlink(fifo.c_str());
}

// A video file's name and an image file's name: each kind is checked before it is opened.
INSTANTIATE_TEST_SUITE_P(Kinds, FifoSource, ::testing::Values("take.avi", "frame.png"),
                         [](const auto& info) { return info.param == "take.avi" ? "video" : "image"; });

TEST(Shutdown, SigtermEndsADaemonWaitingForItsConfigOnAFifo) {
  const std::string fifo = make_fifo("config.toml");
  const std::string output = temp_path("config_output.txt");
  test::DaemonProcess daemon({"--config", fifo}, output);
  // Once the daemon reads the FIFO, hold it open and write nothing: its read waits.
  const int writer = writer_once_read(fifo);
  ASSERT_GE(writer, 0) << "covtrackd never opened its config";
  int exit_status = 0;
  const double took_s = daemon.stop(SIGTERM, exit_status);
  ::close(writer);
  ASSERT_GE(took_s, 0) << "covtrackd ignored SIGTERM while waiting for its config";
  EXPECT_TRUE(WIFSIGNALED(exit_status) && WTERMSIG(exit_status) == SIGTERM) << "status " << exit_status;
  EXPECT_NE(text_of(output).find("covtrackd: SIGTERM before the devices started; nothing was started"),
            std::string::npos)
      << text_of(output);
  ::unlink(fifo.c_str());
}

TEST(Shutdown, AConfigThroughAPipeIsRead) {
  const std::string fifo = make_fifo("piped.toml");
  const std::string output = temp_path("piped_output.txt");
  test::DaemonProcess daemon({"--check", "--config", fifo}, output);
  const int writer = writer_once_read(fifo);
  ASSERT_GE(writer, 0) << "covtrackd never opened its config";
  const std::string config = R"(
[devices.steady]
type = "sim"
sensor_count = 1
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)";
  ASSERT_EQ(::write(writer, config.data(), config.size()), static_cast<ssize_t>(config.size()));
  ::close(writer);  // the end of the text
  const auto exit_status = daemon.wait(10.0);
  ASSERT_TRUE(exit_status) << "covtrackd --check did not end";
  EXPECT_TRUE(WIFEXITED(*exit_status) && WEXITSTATUS(*exit_status) == 0) << text_of(output);
  EXPECT_NE(text_of(output).find(": OK, 1 device(s)"), std::string::npos) << text_of(output);
  ::unlink(fifo.c_str());
}
