// `covtrack emulate-6dof` as a separate process: the real driver configures it through
// the link it creates and gets honest poses; the command then exits 0 on its own.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"
#include "../devices/capture_sink.hpp"
#include "test_support.hpp"

using namespace covtrack;
using namespace std::chrono_literals;

TEST(Emulate6dofCli, DriverTalksToTheCommandAndItExitsZero) {
  const std::string link = ::testing::TempDir() + "/covtrack_cli6_" + std::to_string(::getpid());
  const pid_t pid = fork();
  if (pid == 0) {
    execl(COVTRACK_CLI, COVTRACK_CLI, "emulate-6dof", "--protocol", "fastrak", "--model", "is900",
          "--link", link.c_str(), "--stations", "1,3", "--rate-hz", "100", "--reset-time-s", "0.1",
          "--duration", "4", "--no-truth", nullptr);
    _exit(127);
  }
  for (int i = 0; i < 200 && !std::filesystem::exists(link); ++i) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(std::filesystem::exists(link)) << "the emulator did not create " << link;

  serial6dof::Serial6dofConfig c;
  c.device = "cli";
  c.model = serial6dof::Model::Is900;
  c.port = link;
  c.stations = {{1, "st1", std::nullopt}, {3, "st3", std::nullopt}};
  c.rate_hz = 100;
  c.reset_time_s = 0.15;
  test::CaptureSink sink;
  auto driver = serial6dof::make_serial6dof_driver(c, 0);
  std::stop_source stop;
  std::thread t([&] { EXPECT_TRUE(driver->run(sink, stop.get_token())); });
  int ok = 0;
  bool both = false;
  // Until enough records came, or the emulator's 4 s are nearly over.
  covtrack::testing::eventually(
      [&] {
        std::lock_guard lock(sink.m);
        ok = 0;
        for (const auto& p : sink.poses) {
          ok += p.status != TrackingStatus::Lost;
          both |= p.sensor == "st3";
        }
        return ok > 100 && both;
      },
      3500ms);
  stop.request_stop();
  t.join();
  EXPECT_GT(ok, 100) << "records from the emulator process";
  EXPECT_TRUE(both) << "station 3 was configured on both sides";

  int status = 0;
  for (int i = 0; i < 600 && waitpid(pid, &status, WNOHANG) == 0; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
}

TEST(Emulate6dofCli, WrongModelForProtocolExitsNonZero) {
  const std::string cmd = std::string(COVTRACK_CLI) +
                          " emulate-6dof --protocol flock --model liberty --link /tmp/x --no-truth 2>/dev/null";
  const int rc = std::system(cmd.c_str());
  EXPECT_TRUE(WIFEXITED(rc) && WEXITSTATUS(rc) == 2) << rc;
}
