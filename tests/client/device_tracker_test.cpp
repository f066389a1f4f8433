// A device's heartbeats on an injected clock: unreachable after three missed periods,
// a restart (a new instance id, the old one silent) told from a second publisher (two
// instance ids that both go on).
#include <gtest/gtest.h>

#include "covtrack/client/device_tracker.hpp"

using covtrack::client::DeviceTracker;
using covtrack::client::second_publisher_warning;

namespace {

covtrack::device_status_t heartbeat(std::int64_t instance) {
  covtrack::device_status_t s{};
  s.device = "dev";
  s.instance_id = instance;
  s.host = "pc" + std::to_string(instance);
  s.pid = static_cast<std::int32_t>(100 + instance);
  s.heartbeat_period_us = 1'000'000;
  return s;
}

}  // namespace

// The clock is injected: times in microseconds, heartbeats once a second.
TEST(DeviceTracker, UnreachableAfterThreeMissedHeartbeatsAndBackWithTheNext) {
  DeviceTracker d;
  d.on_heartbeat(heartbeat(7), 1'000'000);
  EXPECT_FALSE(d.check(3'900'000));
  EXPECT_TRUE(d.state().reachable);
  EXPECT_TRUE(d.check(4'000'001));  // 3 periods and a bit: unreachable, said once
  EXPECT_FALSE(d.state().reachable);
  EXPECT_FALSE(d.check(9'000'000));
  d.on_heartbeat(heartbeat(7), 9'500'000);
  EXPECT_TRUE(d.state().reachable);
  EXPECT_EQ(d.state().restarts, 0);
}

TEST(DeviceTracker, ANewInstanceWhoseOldOneFallsSilentIsARestart) {
  DeviceTracker d;
  for (std::int64_t t = 1; t <= 3; ++t) d.on_heartbeat(heartbeat(7), t * 1'000'000);
  for (std::int64_t t = 4; t <= 9; ++t) {  // a new daemon from 4 s on
    d.on_heartbeat(heartbeat(8), t * 1'000'000);
    d.check(t * 1'000'000);
    EXPECT_EQ(d.state().publishers, 1) << t;
  }
  EXPECT_EQ(d.state().restarts, 1);  // once the old one had been silent for 3 periods
  EXPECT_TRUE(d.state().reachable);
}

TEST(DeviceTracker, TwoInstancesThatBothGoOnAreTwoPublishers) {
  DeviceTracker d;
  for (std::int64_t t = 1; t <= 6; ++t) {
    d.on_heartbeat(heartbeat(7), t * 1'000'000);
    if (t >= 3) d.on_heartbeat(heartbeat(9), t * 1'000'000 + 500'000);  // a second daemon from 3.5 s on
    d.check(t * 1'000'000 + 600'000);
  }
  EXPECT_EQ(d.state().publishers, 2);
  EXPECT_EQ(second_publisher_warning("dev", d.state()), "device dev published by two daemons: pc7/107 and pc9/109");
  for (std::int64_t t = 7; t <= 12; ++t) {  // the first one stops: the second goes on alone
    d.on_heartbeat(heartbeat(9), t * 1'000'000 + 500'000);
    d.check(t * 1'000'000 + 600'000);
  }
  EXPECT_EQ(d.state().publishers, 1);
  ASSERT_EQ(d.state().publishing.size(), 1u);
  EXPECT_EQ(d.state().publishing[0].name(), "pc9/109");
  EXPECT_EQ(second_publisher_warning("dev", d.state()), "");
  EXPECT_EQ(d.state().restarts, 0);  // it was never a restart
}

TEST(DeviceTracker, AnInstanceAfterALongSilenceIsARestart) {
  DeviceTracker d;
  d.on_heartbeat(heartbeat(7), 1'000'000);
  EXPECT_TRUE(d.check(10'000'000));
  d.on_heartbeat(heartbeat(8), 20'000'000);
  EXPECT_EQ(d.state().restarts, 1);
  EXPECT_TRUE(d.state().reachable);
}
