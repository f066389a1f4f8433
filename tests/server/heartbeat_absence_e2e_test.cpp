// A dead daemon told from a quiet one: covtrackd with config/sim.toml inside this test's
// network namespace, a client-library Subscriber that sees its streams, then kill -9. The
// subscriber must report both devices unreachable and every stream LOST (from the missing
// heartbeats: no message says so), and a daemon started again must count as a restart.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "covtrack/client/subscriber.hpp"
#include "daemon_process.hpp"
#include "support/wait_for.hpp"

using namespace covtrack;
using namespace std::chrono_literals;

namespace {

const std::string kUrl = "udpm://239.255.76.67:7713?ttl=0";

std::string sim_config() {
  std::ifstream in(COVTRACK_SOURCE_DIR "/config/sim.toml");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

using covtrack::testing::wait_for;

bool all_reachable(const client::Subscriber& sub, std::size_t devices) {
  const auto d = sub.devices();
  if (d.size() != devices) return false;
  for (const auto& [name, state] : d)
    if (!state.reachable) return false;
  return true;
}

}  // namespace

TEST(HeartbeatAbsence, KilledDaemonMakesItsDevicesUnreachableAndItsStreamsLost) {
  auto opened = client::Subscriber::open({.lcm_url = kUrl});
  ASSERT_TRUE(opened) << opened.error().message;
  auto& sub = **opened;
  std::mutex mutex;
  std::set<std::string> reported_lost;  // streams the subscriber reported LOST for an unreachable device
  ASSERT_TRUE(sub.on_pose(".*", [&](const client::TrackedTransform& t) {
    if (!t.device_unreachable) return;
    EXPECT_TRUE(t.lost());
    std::lock_guard lock(mutex);
    reported_lost.insert(t.stream.key());
  }));
  const auto lost_count = [&] {
    std::lock_guard lock(mutex);
    return reported_lost.size();
  };

  auto daemon = std::make_unique<test::DaemonProcess>(sim_config(), kUrl);
  // sim.toml: "optical" (head, wand) and "magnetic" (one sensor), heartbeats at 1 Hz.
  ASSERT_TRUE(wait_for([&] { return all_reachable(sub, 2) && sub.streams().size() == 3; }))
      << sub.devices().size() << " devices, " << sub.streams().size() << " streams";
  const auto before = sub.devices();
  EXPECT_EQ(before.at("optical").status.heartbeat_period_us, 1'000'000);
  EXPECT_EQ(before.at("optical").status.pid, daemon->pid());
  EXPECT_EQ(before.at("optical").publishers, 1);
  EXPECT_EQ(lost_count(), 0u) << "a live daemon was reported unreachable";

  int status = 0;
  ASSERT_GE(daemon->stop(SIGKILL, status), 0.0);
  ASSERT_TRUE(wait_for([&] { return lost_count() == 3; })) << lost_count() << " of 3 streams reported LOST";
  for (const auto& [name, device] : sub.devices()) EXPECT_FALSE(device.reachable) << name;
  for (const auto& s : sub.streams()) {
    ASSERT_TRUE(s.latest) << s.id.key();
    EXPECT_TRUE(s.latest->lost()) << s.id.key();
    EXPECT_TRUE(s.latest->device_unreachable) << s.id.key();
  }

  // Started again: reachable, a new instance, counted as a restart, streams delivered again.
  daemon = std::make_unique<test::DaemonProcess>(sim_config(), kUrl);
  ASSERT_TRUE(wait_for([&] {
    if (!all_reachable(sub, 2)) return false;
    for (const auto& s : sub.streams())
      if (!s.latest || s.latest->device_unreachable || s.counters.restarts != 1) return false;
    return true;
  })) << "the new daemon's streams were not followed";
  const auto after = sub.devices();
  EXPECT_NE(after.at("optical").status.instance_id, before.at("optical").status.instance_id);
  EXPECT_EQ(after.at("optical").status.pid, daemon->pid());
  EXPECT_EQ(after.at("optical").restarts, 1);
  EXPECT_EQ(after.at("optical").publishers, 1);
  for (const auto& s : sub.streams()) EXPECT_EQ(s.counters.lost, 0) << s.id.key() << ": a restart is no loss";
}
