// The daemon's stop has a limit. A driver blocked in a call that ignores the stop request
// (here a real open() of a FIFO nobody writes, as a driver that did not check its
// source's kind first would be) is named once daemon.stop_timeout_s has passed, while a
// well-behaved device beside it stops at once; the host then waits for nothing more.
// A real Host on LCM's in-process provider (memq://), so no network is involved.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <future>

#include <lcm/lcm-cpp.hpp>

#include "config.hpp"
#include "host.hpp"

using namespace covtrack;
using namespace std::chrono_literals;

namespace {

class BlockedInOpen final : public Driver {
 public:
  BlockedInOpen(std::string fifo, std::promise<void>& entered, std::atomic<bool>& returned)
      : fifo_(std::move(fifo)), entered_(entered), returned_(returned) {}
  Result<void> run(SampleSink&, std::stop_token) override {
    entered_.set_value();
    const int fd = ::open(fifo_.c_str(), O_RDONLY);  // until a writer opens the FIFO
    if (fd >= 0) ::close(fd);
    returned_ = true;
    return {};
  }

 private:
  std::string fifo_;
  std::promise<void>& entered_;
  std::atomic<bool>& returned_;
};

}  // namespace

TEST(HostStop, NamesTheDeviceThatDidNotStopAndWaitsNoLonger) {
  const std::string fifo = ::testing::TempDir() + "/covtrack_host_stop_" + std::to_string(::getpid());
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto config = server::parse_config(R"(
[daemon]
stop_timeout_s = 0.5

[devices.steady]
type = "sim"
sensor_count = 1
rate_hz = 50
sigma_m = [0.001, 0.001, 0.001]
sigma_rad = [0.001, 0.001, 0.001]
)",
                                     "host_stop.toml");
  ASSERT_TRUE(config) << config.error().message;
  std::promise<void> entered;
  std::atomic<bool> returned{false};
  const server::DriverFactory wedged = [&](std::uint64_t) -> std::unique_ptr<Driver> {
    return std::make_unique<BlockedInOpen>(fifo, entered, returned);
  };
  config->devices.push_back({"wedged", "test", wedged});
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  server::Host host(*config, lcm);
  host.start();
  ASSERT_EQ(entered.get_future().wait_for(10s), std::future_status::ready);

  const auto asked = std::chrono::steady_clock::now();
  const auto stuck = host.stop();
  const double waited_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
  ASSERT_EQ(stuck.size(), 1u);
  EXPECT_EQ(stuck[0], "device 'wedged' (test) did not stop within 0.5 s");
  EXPECT_GE(waited_s, 0.5);  // the driver had its time
  EXPECT_LT(waited_s, 5.0);  // and no more: the join has a limit
  EXPECT_FALSE(returned);

  // Released (a writer lets its open() return), the driver ends and nothing is stuck.
  const int writer = ::open(fifo.c_str(), O_WRONLY);  // at once: a reader is waiting
  ASSERT_GE(writer, 0);
  ::close(writer);
  EXPECT_TRUE(host.stop().empty());
  EXPECT_TRUE(returned);
  ::unlink(fifo.c_str());
}
