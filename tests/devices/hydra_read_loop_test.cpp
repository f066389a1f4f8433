// The Razer Hydra driver's read loop over a scripted hidraw node (scripted_hid.hpp says
// why not a real one) on simulated time: reports queued while the reader was held up are
// timed one period apart, a full kernel queue is not published, silence is LOST once and
// repeats the mode switch, reports that parse keep it alive and reports that do not end
// the run, an unplugged base leaves both controllers LOST, and the reports read before it
// went, in the middle of a backlog, are published.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "capture_sink.hpp"
#include "covtrack/devices/hydra/hydra_driver.hpp"
#include "hydra_report.hpp"
#include "manual_clock.hpp"
#include "scripted_hid.hpp"

using namespace covtrack;
using namespace covtrack::hydra;
using namespace std::chrono_literals;

namespace {

constexpr double kRateHz = 250;
constexpr std::int64_t kPeriodUs = 4000;
constexpr auto kStep = 5ms;  // of the simulated clock: one read per step

HydraConfig config() {
  HydraConfig c;
  c.device = "hydra";
  c.hid_path = test::ScriptedHid::kPath;
  c.covariance = hydra_default_covariance();
  c.rate_hz = kRateHz;
  return c;
}

// Both hands held still in front of the base, left at x < 0 (where the driver assumes it).
std::array<std::uint8_t, kReportSize> still_hands() {
  HydraReport r;
  r.controllers[0].position_m = Vec3(-0.2, 0.1, -0.3);
  r.controllers[1].position_m = Vec3(0.2, 0.1, -0.3);
  return build_hydra_report(r);
}

void queue_still_hands(int count) {
  for (int i = 0; i < count; ++i) test::scripted_hid().queue(still_hands());
}

// The driver in a thread of its own on `clock`, over the scripted device (reset first).
class RunningHydra {
 public:
  RunningHydra(const HydraConfig& c, test::ManualClock& clock) : clock_(clock) {
    test::scripted_hid().reset();
    clock_.join();
    thread_ = std::jthread([this, c](std::stop_token stop) {
      result_ = make_hydra_driver(c, clock_)->run(sink, stop);
      returned_ = true;
      clock_.leave();
    });
    EXPECT_TRUE(clock_.settle()) << "the driver did not reach its first read";
  }
  ~RunningHydra() {
    thread_.request_stop();
    thread_.join();
  }

  bool returned() const { return returned_; }
  // Once returned().
  const Result<void>& result() const { return result_; }

  std::vector<PoseSample> poses_of(const std::string& sensor, TrackingStatus status) {
    std::lock_guard l(sink.m);
    std::vector<PoseSample> out;
    for (const PoseSample& s : sink.poses)
      if (s.sensor == sensor && s.status == status) out.push_back(s);
    return out;
  }

  test::CaptureSink sink;

 private:
  test::ManualClock& clock_;
  Result<void> result_;
  std::atomic<bool> returned_ = false;
  std::jthread thread_;
};

// The times of `count` reports read at once at `read_us`: one period apart, the last then.
// Without the first: the plausibility gate holds a session's first pose until the next
// one agrees with it (motion_gate.hpp), and publishes that next one.
std::vector<std::int64_t> one_period_apart_but_the_first(int count, std::int64_t read_us) {
  std::vector<std::int64_t> t;
  for (int k = 1; k < count; ++k) t.push_back(read_us - (count - 1 - k) * kPeriodUs);
  return t;
}

// Queues `report` before each step of `clock` until `done` (at most 3 s); how many it
// queued.
int queue_one_a_step_until(test::ManualClock& clock, std::span<const std::uint8_t> report,
                           const std::function<bool()>& done) {
  int sent = 0;
  EXPECT_TRUE(clock.run_until(
      [&] {
        if (done()) return true;
        test::scripted_hid().queue(report), ++sent;
        return false;
      },
      3s));
  return sent;
}

std::vector<std::int64_t> times_of(const std::vector<PoseSample>& poses) {
  std::vector<std::int64_t> t;
  for (const PoseSample& s : poses) t.push_back(s.measurement_time_us);
  return t;
}

}  // namespace

// A reader held up finds reports queued in the kernel, measured one period apart: stamped
// all "now", all but the last would be late by up to the hold-up.
TEST(HydraReadLoop, QueuedReportsAreTimedOnePeriodApartTheNewestAtTheRead) {
  test::ManualClock clock(kStep);
  RunningHydra run(config(), clock);
  queue_still_hands(10);
  ASSERT_TRUE(clock.run_for(kStep));
  const std::int64_t read_us = clock.now_us();
  EXPECT_EQ(test::scripted_hid().waiting(), 0u) << "one read takes all that waits";
  for (const std::string sensor : {"left", "right"}) {
    const auto ok = run.poses_of(sensor, TrackingStatus::Ok);
    EXPECT_EQ(times_of(ok), one_period_apart_but_the_first(10, read_us)) << sensor;
  }
  EXPECT_EQ(run.sink.errors, 0);
}

// hidraw keeps 63 reports per reader and drops newer ones when full: a full queue holds
// the hold-up's oldest reports, of unknown age. One fewer is a queue that was not full.
TEST(HydraReadLoop, AFullKernelQueueIsCountedNotPublished) {
  test::ManualClock clock(kStep);
  RunningHydra run(config(), clock);
  queue_still_hands(63);
  ASSERT_TRUE(clock.run_for(kStep));
  EXPECT_EQ(test::scripted_hid().waiting(), 0u);
  EXPECT_TRUE(run.poses_of("left", TrackingStatus::Ok).empty());
  EXPECT_EQ(run.sink.errors, 1) << "one error says why the reports are not published";

  queue_still_hands(62);
  ASSERT_TRUE(clock.run_for(kStep));
  const auto ok = run.poses_of("left", TrackingStatus::Ok);
  EXPECT_EQ(times_of(ok), one_period_apart_but_the_first(62, clock.now_us()));
  EXPECT_EQ(run.sink.errors, 1);
}

TEST(HydraReadLoop, SilenceIsLostOnceAndRepeatsTheModeSwitchEveryTwoSeconds) {
  test::ManualClock clock(kStep);
  RunningHydra run(config(), clock);
  queue_still_hands(2);  // the first held by the gate, the second published
  ASSERT_TRUE(clock.run_for(kStep));
  const auto last = run.poses_of("left", TrackingStatus::Ok);
  ASSERT_EQ(last.size(), 1u);

  // Silent past watchdog_periods (4 periods, 16 ms): LOST, once, at the last pose.
  ASSERT_TRUE(clock.run_for(100ms));
  for (const std::string sensor : {"left", "right"})
    EXPECT_EQ(run.poses_of(sensor, TrackingStatus::Lost).size(), 1u) << sensor;
  EXPECT_TRUE(run.poses_of("left", TrackingStatus::Lost)[0].T_parent_child.isApprox(last[0].T_parent_child));
  EXPECT_EQ(test::scripted_hid().feature_reports(), 0);

  // A base that fell back to gamepad mode sends nothing: after 2 s of silence the switch
  // to motion mode is sent again, then every 2 s.
  ASSERT_TRUE(clock.run_until([] { return test::scripted_hid().feature_reports() == 1; }, 2100ms));
  EXPECT_GT(clock.elapsed_s(), 2.0);
  ASSERT_TRUE(clock.run_until([] { return test::scripted_hid().feature_reports() == 2; }, 2100ms));
  EXPECT_GT(clock.elapsed_s(), 4.0);
  EXPECT_EQ(run.poses_of("left", TrackingStatus::Lost).size(), 1u);

  queue_still_hands(2);  // LOST restarted the gate
  ASSERT_TRUE(clock.run_for(kStep));
  EXPECT_EQ(run.poses_of("right", TrackingStatus::Ok).size(), 2u);
  EXPECT_FALSE(run.returned());
}

// The counterpart of the silence test above and of the one below: reports that parse, one
// per read for longer than the silence and no-valid-report limits, keep the device running
// and are all published.
TEST(HydraReadLoop, ReportsThatParseKeepItAlive) {
  HydraConfig c = config();
  c.no_valid_frames_s = 0.5;
  test::ManualClock clock(kStep);
  RunningHydra run(c, clock);
  const int sent = queue_one_a_step_until(clock, still_hands(), [&] { return clock.elapsed_s() >= 2.5; });
  EXPECT_FALSE(run.returned());
  EXPECT_EQ(run.poses_of("left", TrackingStatus::Ok).size(), static_cast<std::size_t>(sent - 1));
  EXPECT_TRUE(run.poses_of("left", TrackingStatus::Lost).empty());
  EXPECT_EQ(test::scripted_hid().feature_reports(), 0) << "no mode switch while reports arrive";
}

// Reports arrive but none parses (a base in another mode, a wrong interface): they are
// counted, never published, and keep nothing alive.
TEST(HydraReadLoop, ReportsThatDoNotParseAreCountedAndEndTheRun) {
  HydraConfig c = config();
  c.no_valid_frames_s = 0.5;
  test::ManualClock clock(kStep);
  RunningHydra run(c, clock);
  const std::uint8_t gamepad_report[10] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  const int sent = queue_one_a_step_until(clock, gamepad_report, [&] { return run.returned(); });
  ASSERT_TRUE(run.returned());
  ASSERT_FALSE(run.result());
  const int read = sent - static_cast<int>(test::scripted_hid().waiting());
  EXPECT_GE(clock.elapsed_s(), 0.5);
  EXPECT_LT(clock.elapsed_s(), 0.6);
  EXPECT_NE(run.result().error().message.find(fmt::format("{} reports that did not parse", read)), std::string::npos)
      << run.result().error().message;
  EXPECT_EQ(run.sink.errors, read);
  EXPECT_TRUE(run.poses_of("left", TrackingStatus::Ok).empty());
  EXPECT_FALSE(run.poses_of("left", TrackingStatus::Lost).empty());
}

TEST(HydraReadLoop, AnUnpluggedBaseEndsTheRunWithBothControllersLost) {
  test::ManualClock clock(kStep);
  RunningHydra run(config(), clock);
  queue_still_hands(2);
  ASSERT_TRUE(clock.run_for(kStep));
  ASSERT_EQ(run.poses_of("right", TrackingStatus::Ok).size(), 1u);
  test::scripted_hid().unplug();
  ASSERT_TRUE(clock.run_until([&] { return run.returned(); }, 1s));
  ASSERT_FALSE(run.result());
  EXPECT_NE(run.result().error().message.find("device disconnected"), std::string::npos)
      << run.result().error().message;
  std::lock_guard l(run.sink.m);
  ASSERT_GE(run.sink.poses.size(), 4u);
  for (std::size_t k = run.sink.poses.size() - 2; k < run.sink.poses.size(); ++k)
    EXPECT_EQ(run.sink.poses[k].status, TrackingStatus::Lost) << run.sink.poses[k].sensor;
  EXPECT_FALSE(test::scripted_hid().open()) << "the device is closed when the run ends";
}

// The base unplugged in the middle of a backlog: the reports read before it went are kept,
// timed as any backlog, and published; the failure shows at the next read and ends the
// run with both controllers LOST.
TEST(HydraReadLoop, ReportsReadBeforeAnUnplugMidBacklogArePublished) {
  test::ManualClock clock(kStep);
  RunningHydra run(config(), clock);
  queue_still_hands(2);  // the session's start (the gate holds the first pose)
  ASSERT_TRUE(clock.run_for(kStep));
  ASSERT_EQ(run.poses_of("right", TrackingStatus::Ok).size(), 1u);
  queue_still_hands(10);
  test::scripted_hid().unplug_after(6);
  ASSERT_TRUE(clock.run_for(kStep));
  const std::int64_t read_us = clock.now_us();
  ASSERT_TRUE(clock.run_until([&] { return run.returned(); }, 1s));
  ASSERT_FALSE(run.result());
  EXPECT_NE(run.result().error().message.find("device disconnected"), std::string::npos)
      << run.result().error().message;
  for (const std::string sensor : {"left", "right"}) {
    const auto ok = run.poses_of(sensor, TrackingStatus::Ok);
    ASSERT_EQ(ok.size(), 7u) << sensor << ": the six reports read before the unplug are not all published";
    std::vector<std::int64_t> times, expected;
    for (std::size_t k = 1; k < ok.size(); ++k) times.push_back(ok[k].measurement_time_us);
    for (int k = 5; k >= 0; --k) expected.push_back(read_us - k * kPeriodUs);
    EXPECT_EQ(times, expected) << sensor << ": one period apart, the last at the read";
    EXPECT_FALSE(run.poses_of(sensor, TrackingStatus::Lost).empty()) << sensor;
  }
  EXPECT_EQ(test::scripted_hid().waiting(), 4u) << "the reports queued after the unplug stay unread";
}
