// The lenz driver against the emulator, in one process over a real pseudo-terminal:
// honesty of the reported uncertainty against the emulator's true train position, the
// LI-USB framing, a port that disappears mid-run and comes back, and a line of pure
// noise, which must end the run as a failure (the daemon then resets the device).
// Driver and emulator run on one simulated clock (manual_clock.hpp) that the test moves
// in steps, waiting after each step until both have caught up: the bytes go over the
// real terminal, but no test waits for time to pass, and a loaded machine only makes
// the run slower, never different.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <random>
#include <set>
#include <thread>

#include <Eigen/Cholesky>

#include "capture_sink.hpp"
#include "covtrack/devices/lenz/lenz_driver.hpp"
#include "covtrack/devices/serial/pseudo_terminal.hpp"
#include "covtrack/emulators/lenz/lenz_emulator.hpp"
#include "dead_reckoning.hpp"
#include "layout_config.hpp"
#include "manual_clock.hpp"

using namespace covtrack;
using namespace covtrack::lenz;
using namespace std::chrono_literals;

namespace {

std::shared_ptr<const TrackLayout> short_layout() {
  auto layout = load_layout(COVTRACK_SOURCE_DIR "/tests/data/lenz_short_layout.toml");
  EXPECT_TRUE(layout) << layout.error().message;
  return std::make_shared<const TrackLayout>(layout ? std::move(*layout) : TrackLayout{});
}

// Accelerate, cruise, slow down, cruise, stop, wait, restart (one cycle is about 9 s).
const std::vector<SpeedStep> kProfile{{0.5, 1.5}, {0.15, 1}, {0, 1}, {0.4, 1.5}};

// The simulated clock moves in steps this long. A crossing then reaches the driver at
// most two steps after it happened (the emulator sees it at the step's end, the driver
// reads it in that step or the next), well within the 50 ms the dead reckoning allows.
constexpr auto kStep = 5ms;

// The driver's pose period (the Rig's rate_hz: 50).
constexpr std::int64_t kSamplePeriodUs = 20'000;

// A driver's own clock that can hold the driver up once, between its port's answer and its
// next look at the clock, as when the process is stopped or preempted as its poll returns:
// the read saw the port as it was before the hold-up, the clock after it.
class HoldOnTheWayBack final : public DriverClock {
 public:
  explicit HoldOnTheWayBack(test::ManualClock& clock) : clock_(clock) {}
  void hold_after_the_next_wait(duration how_long) { hold_ = how_long; }

  time_point now() const override {
    if (std::exchange(waited_, false))
      if (const duration hold = hold_.exchange(duration::zero()); hold > duration::zero()) clock_.advance(hold);
    return clock_.now();
  }
  std::int64_t now_us() const override { return clock_.now_us(); }
  std::chrono::milliseconds io_timeout(std::stop_token stop, time_point due, std::chrono::milliseconds cap) override {
    const auto timeout = clock_.io_timeout(stop, due, cap);
    waited_ = true;
    return timeout;
  }
  bool sleep_until(std::stop_token stop, time_point deadline) override { return clock_.sleep_until(stop, deadline); }

 private:
  test::ManualClock& clock_;
  mutable std::atomic<duration> hold_{duration::zero()};  // set by the test, taken by the driver's thread
  mutable bool waited_ = false;                            // the driver's thread only
};

// A sink that can hold the driver up once inside its report of bytes it read: after the
// read and its time stamp, before the driver acts on the bytes and publishes (its thread
// preempted there, or the raw stream's publish blocked). Armed, it holds the first read
// that begins with a feedback broadcast, or with `when_a_sample_is_due` the first such
// read after which the driver publishes, by moving the driver's clock on.
class HoldInsideARead final : public test::CaptureSink {
 public:
  void arm(test::ManualClock& driver_clock, std::chrono::milliseconds hold, bool when_a_sample_is_due) {
    driver_clock_ = &driver_clock;
    when_a_sample_is_due_ = when_a_sample_is_due;
    hold_ = hold;
  }
  bool held() const { return held_; }
  std::int64_t last_pose_us() const { return last_pose_us_; }

  void pose(const PoseSample& s) override {
    CaptureSink::pose(s);
    last_pose_us_ = s.measurement_time_us;
  }
  void raw(ByteDirection direction, const std::uint8_t* data, std::size_t n) override {
    CaptureSink::raw(direction, data, n);
    const bool feedback = direction == ByteDirection::FromDevice && n > 0 && (data[0] & 0xF0) == 0x40;
    // The driver publishes at most once a period: one is due in this loop once a period
    // has passed since the last.
    const bool sample_due = driver_clock_ && driver_clock_->now_us() - last_pose_us_ >= kSamplePeriodUs;
    if (hold_ == std::chrono::milliseconds::zero() || !feedback || (when_a_sample_is_due_ && !sample_due)) return;
    driver_clock_->advance(std::exchange(hold_, std::chrono::milliseconds::zero()));
    held_ = true;
  }

 private:
  // Set by the test before it moves the clocks, then used by the driver's thread alone
  // (ManualClock::advance and settle order the two).
  test::ManualClock* driver_clock_ = nullptr;
  std::chrono::milliseconds hold_{0};
  bool when_a_sample_is_due_ = false;
  std::atomic<std::int64_t> last_pose_us_{0};
  std::atomic<bool> held_{false};
};

struct Rig {
  // `driver_clock_of_its_own`: the driver's time moves only when the test moves it
  // (run_both_for), so that the test can hold the driver up while the emulator runs.
  explicit Rig(Interface interface, const std::string& name, bool driver_clock_of_its_own = false)
      : driver_clock(driver_clock_of_its_own ? own_driver_clock : clock) {
    LenzEmulatorOptions options;
    options.layout = short_layout();
    options.interface = interface;
    options.profile = kProfile;
    options.start_s = 0.1;
    options.link_path = ::testing::TempDir() + "/covtrack_lenz_" + name + "_" + std::to_string(::getpid());
    auto created = LenzEmulator::create(options, clock);
    EXPECT_TRUE(created) << created.error().message;
    emulator = std::move(*created);
    clock.join();
    emulator_thread = std::jthread([this](std::stop_token stop) { emulator->run(stop, nullptr); });

    config.device = "train";
    config.port = emulator->device_path();
    config.interface = interface;
    config.baud = interface == Interface::LiUsb ? 57600 : 19200;
    config.layout = options.layout;
    config.rate_hz = 1e6 / kSamplePeriodUs;
    config.keepalive_s = 0.2;
    config.link_timeout_s = 1.0;
    config.no_valid_frames_s = 1.0;
    config.reconnect_s = 0.1;
    driver = make_lenz_driver(config, driver_clock_of_its_own ? static_cast<DriverClock&>(hold_on_the_way_back) : clock);
    driver_clock.join();
    driver_thread = std::jthread([this](std::stop_token stop) {
      result = driver->run(sink, stop);
      returned = true;
      driver_clock.leave();
    });
    EXPECT_TRUE(clock.settle() && driver_clock.settle()) << "driver or emulator did not start";
  }
  ~Rig() {
    driver_thread.request_stop();
    driver_thread.join();
    emulator_thread.request_stop();
  }
  // Moves both clocks on together, a step at a time (a driver with a clock of its own).
  bool run_both_for(std::chrono::nanoseconds how_long) {
    for (std::chrono::nanoseconds done{0}; done < how_long; done += kStep) {
      clock.advance(kStep);
      own_driver_clock.advance(kStep);
      if (!clock.settle() || !own_driver_clock.settle()) {
        ADD_FAILURE() << "a loop did not catch up with the simulated clock at " << clock.elapsed_s() << " s";
        return false;
      }
    }
    return true;
  }
  std::vector<PoseSample> poses() {
    std::lock_guard lock(sink.m);
    return sink.poses;
  }
  std::vector<std::uint8_t> raw() {
    std::lock_guard lock(sink.m);
    return sink.raw_bytes;
  }

  // First: they outlive the threads that wait on them.
  test::ManualClock clock{kStep};             // the emulator's, and the driver's unless it has its own
  test::ManualClock own_driver_clock{kStep};  // unused unless asked for
  test::ManualClock& driver_clock;
  HoldOnTheWayBack hold_on_the_way_back{own_driver_clock};  // the driver's, when it has its own
  std::unique_ptr<LenzEmulator> emulator;
  LenzConfig config;
  std::unique_ptr<Driver> driver;
  HoldInsideARead sink;
  Result<void> result;
  std::atomic<bool> returned{false};  // before a stop: the driver gave up on a valid stream
  std::jthread emulator_thread, driver_thread;
};

bool contains(const std::vector<std::uint8_t>& haystack, const std::vector<std::uint8_t>& needle) {
  return std::search(haystack.begin(), haystack.end(), needle.begin(), needle.end()) != haystack.end();
}

// The along-track coordinate of a point on the track (nearest, at 1 mm resolution).
double project(const TrackLayout& layout, const Vec3& p) {
  double best_s = 0, best_d = 1e9;
  for (double s = 0; s < layout.length_m(); s += 0.001) {
    const double d = (layout.pose_at(s).translation() - p).squaredNorm();
    if (d < best_d) best_d = d, best_s = s;
  }
  return best_s;
}

double loop_distance(const TrackLayout& layout, double a, double b) {
  const double half = layout.length_m() / 2;
  return std::abs(layout.wrap(a - b + half) - half);
}

// How well the locomotive's DEGRADED (dead-reckoned) poses hold the emulator's truth.
struct Honesty {
  int degraded = 0, inside = 0, pose_inside = 0;
  double width_sum = 0, error_sum = 0;
  double inside_share() const { return double(inside) / degraded; }
  double pose_inside_share() const { return double(pose_inside) / degraded; }
};

Honesty honesty_of(const std::vector<PoseSample>& poses, const LenzEmulator& emulator) {
  const TrackLayout& layout = emulator.layout();
  Honesty h;
  for (const auto& p : poses) {
    if (p.sensor != "loco" || p.status != TrackingStatus::Degraded) continue;
    ++h.degraded;
    const double s_true = emulator.true_s_at(p.measurement_time_us);
    const double s_est = project(layout, p.T_parent_child.translation());
    const double half_width = kZ99 * std::sqrt(p.covariance(0, 0));
    const double error = loop_distance(layout, s_true, s_est);
    h.inside += error <= half_width + 0.001;  // 1 mm: the projection's resolution
    h.width_sum += 2 * half_width;
    h.error_sum += error;
    const Vec6 e = boxminus(layout.pose_at(s_true), p.T_parent_child);
    h.pose_inside += e.dot(p.covariance.ldlt().solve(e)) <= 16.812;
  }
  std::printf("along-track 99%% interval holds the truth %.4f of %d samples; 6-D 99%% ellipsoid %.4f; "
              "mean width %.4f m, mean |error| %.4f m\n",
              h.inside_share(), h.degraded, h.pose_inside_share(), h.width_sum / h.degraded, h.error_sum / h.degraded);
  return h;
}

}  // namespace

TEST(LenzDriver, UncertaintyContainsTheTruthOverSpeedChangesAndAStop) {
  Rig rig(Interface::Li101f, "honesty");
  ASSERT_TRUE(rig.clock.run_for(9s));
  const auto poses = rig.poses();
  const TrackLayout& layout = rig.emulator->layout();
  std::set<std::string> sensors;
  for (const auto& p : poses) sensors.insert(p.sensor);
  const Honesty h = honesty_of(poses, *rig.emulator);
  ASSERT_GT(h.degraded, 300);
  EXPECT_GE(h.inside_share(), 0.99);
  EXPECT_GE(h.pose_inside_share(), 0.97);
  EXPECT_LT(h.width_sum / h.degraded, layout.length_m() / layout.sections().size());
  EXPECT_EQ(sensors.size(), 3u);
  EXPECT_EQ(rig.sink.errors, 0);
  EXPECT_FALSE(rig.returned) << "a valid stream was failed: " << (rig.result ? "" : rig.result.error().message);
  // The startup queries went out and the replies came back, all on the raw stream.
  const auto raw = rig.raw();
  EXPECT_TRUE(contains(raw, {0xF0, 0xF0}));
  EXPECT_TRUE(contains(raw, {0x21, 0x21, 0x00}));
  EXPECT_TRUE(contains(raw, {0x63, 0x21, 0x36, 0x00, 0x74}));
  EXPECT_TRUE(contains(raw, {0x42, 64, 0x80, 0x42 ^ 64 ^ 0x80}));  // module 65, inputs 1-4
  EXPECT_GT(rig.emulator->broadcasts_sent(), 5u);
}

// Line noise whose XOR byte happens to check: broadcasts that claim a section far from
// the train (and clear the one it is on). Believed, each would restart the estimate
// there, confidently wrong until the next crossing; the driver asks the module again,
// hears the true inputs, and drops the forged change.
TEST(LenzDriver, ForgedFeedbackNamingAFarSectionIsAskedAgainAndDropped) {
  Rig rig(Interface::Li101f, "forged");
  const TrackLayout& layout = rig.emulator->layout();
  const auto n = layout.sections().size();
  int forged = 0;
  std::mt19937 rng(7);
  while (rig.clock.elapsed_s() < 9.0) {
    ASSERT_TRUE(rig.clock.run_for(150ms));  // paces the noise
    const std::size_t here = layout.section_at(rig.emulator->true_s_at(rig.clock.now_us()));
    const std::size_t far = (here + 3 + rng() % (n - 5)) % n;  // neither neighbour, nor here
    const auto& in = layout.sections()[far].input;
    const bool upper = in.input > 4;
    const auto bit = static_cast<std::uint8_t>(1u << ((in.input - 1) % 4));
    rig.emulator->forge_feedback({static_cast<std::uint8_t>(in.module - 1),
                                  static_cast<std::uint8_t>(0x40 | (upper ? 0x10 : 0) | bit)});
    ++forged;
  }
  ASSERT_TRUE(rig.clock.run_for(150ms));  // the last forged change is asked for again too
  const Honesty h = honesty_of(rig.poses(), *rig.emulator);
  ASSERT_GT(h.degraded, 300);
  EXPECT_GE(h.inside_share(), 0.99);
  EXPECT_GE(h.pose_inside_share(), 0.97);
  // Each forged change was dropped as noise and counted (a few may coincide with a true
  // report of the same nibble, which then confirms or replaces it).
  std::printf("%d forged broadcasts, %d errors counted\n", forged, rig.sink.errors);
  EXPECT_GE(rig.sink.errors, forged * 8 / 10);
  EXPECT_LE(rig.sink.errors, forged);
  EXPECT_FALSE(rig.returned) << (rig.result ? "" : rig.result.error().message);
}

// Hold-ups of the driver in simulated time: the driver runs on its own clock, which the test
// stops while the emulator's runs on.
constexpr auto kHold = 300ms;

// Runs both clocks until the locomotive is `lead` (to a step less) before a section
// boundary at speed (10 cm or more in a hold-up): a hold-up that starts within `lead` has
// the crossing in it.
bool run_to_just_before_a_crossing(Rig& rig, std::chrono::milliseconds lead = 25ms) {
  const TrackLayout& layout = rig.emulator->layout();
  const auto s_in = [&](std::chrono::milliseconds ahead) {
    return rig.emulator->true_s_at(rig.clock.now_us() + std::chrono::microseconds(ahead).count());
  };
  const auto crossing_within = [&](std::chrono::milliseconds ahead) {
    return layout.section_at(s_in(ahead)) != layout.section_at(s_in(0ms));
  };
  while (rig.clock.elapsed_s() < 2 || !crossing_within(lead) || crossing_within(lead - kStep) ||
         layout.wrap(s_in(kHold) - s_in(0ms)) < 0.1) {
    if (rig.clock.elapsed_s() > 20) {
      ADD_FAILURE() << "no crossing at speed in 20 s";
      return false;
    }
    if (!rig.run_both_for(kStep)) return false;
  }
  return true;
}

// How the locomotive's poses from `from_us` on hold the truth, 0.1 s on.
Honesty honesty_after(Rig& rig, std::int64_t from_us) {
  if (!rig.run_both_for(100ms)) return {};
  std::vector<PoseSample> after;
  for (const auto& p : rig.poses())
    if (p.measurement_time_us >= from_us) after.push_back(p);
  return honesty_of(after, *rig.emulator);
}

// The daemon held up (its machine stalled it) while a busy bus queued more than one read's
// worth of bytes ahead of a crossing. The crossing may have waited the whole hold-up,
// wherever it lies in the backlog, and the estimate must allow for that.
TEST(LenzDriver, ACrossingDeepInTheBacklogOfAHoldUpIsAllowedTheWholeHoldUp) {
  Rig rig(Interface::Li101f, "held", true);
  ASSERT_TRUE(run_to_just_before_a_crossing(rig));
  // Another part of the layout reporting inputs that did not change: 100 broadcasts, 400
  // bytes, of an RS-bus module this layout does not watch (module 91).
  for (int i = 0; i < 100; ++i) rig.emulator->forge_feedback({90, 0x40});
  const auto crossings_before = rig.emulator->broadcasts_sent();
  ASSERT_TRUE(rig.clock.run_for(kHold));  // the driver's clock stands still
  ASSERT_EQ(rig.emulator->broadcasts_sent(), crossings_before + 1) << "the crossing was not in the hold-up";
  const std::int64_t hold_end_us = rig.clock.now_us();
  rig.own_driver_clock.advance(kHold);  // and moves on all at once when the driver runs again
  ASSERT_TRUE(rig.own_driver_clock.settle());
  const Honesty h = honesty_after(rig, hold_end_us);
  ASSERT_GE(h.degraded, 5);
  EXPECT_EQ(h.inside, h.degraded) << "poses after the hold-up miss the truth: the crossing read late was not allowed for";
  EXPECT_EQ(rig.sink.errors, 0);
}

// The driver held up on its way back from a read that found nothing: the read looked
// before the hold-up, so the crossing that came during it waited the whole hold-up for the
// next read, and until that read the estimate must allow for a crossing unread that long.
TEST(LenzDriver, AHoldUpAfterAnEmptyReadIsAllowedForBeforeAndAfterTheNextRead) {
  Rig rig(Interface::Li101f, "held_after_read", true);
  ASSERT_TRUE(run_to_just_before_a_crossing(rig));
  rig.hold_on_the_way_back.hold_after_the_next_wait(kHold);
  rig.own_driver_clock.advance(kStep);  // the driver reads (the crossing has not come), then is held up
  ASSERT_TRUE(rig.own_driver_clock.settle());
  const auto crossings_before = rig.emulator->broadcasts_sent();
  ASSERT_TRUE(rig.clock.run_for(kStep + kHold));  // the emulator's clock catches up
  ASSERT_EQ(rig.emulator->broadcasts_sent(), crossings_before + 1) << "the crossing was not in the hold-up";
  ASSERT_EQ(rig.own_driver_clock.now(), rig.clock.now());
  const Honesty h = honesty_after(rig, rig.clock.now_us());
  ASSERT_GE(h.degraded, 5);
  EXPECT_EQ(h.inside, h.degraded) << "poses after the hold-up miss the truth: the unseen time was not allowed for";
  EXPECT_EQ(rig.sink.errors, 0);
}

// Moves both clocks a step at a time until the sink has held the driver up (at most 0.2 s).
bool run_until_held(Rig& rig) {
  for (auto waited = 0ms; !rig.sink.held(); waited += kStep) {
    if (waited > 200ms) {
      ADD_FAILURE() << "the driver read no feedback broadcast to be held up in";
      return false;
    }
    if (!rig.run_both_for(kStep)) return false;
  }
  return true;
}

// The driver held up after it read a crossing and before it acted on it: the crossing came
// when the read found it, not when the driver got round to it. Timed by the driver's
// clock after the hold-up, it would seem kHold later than it was, and the poses after
// would lag the train by the distance covered in the hold-up.
TEST(LenzDriver, ACrossingActedOnLateIsTimedByItsRead) {
  Rig rig(Interface::Li101f, "held_in_crossing_read", true);
  ASSERT_TRUE(run_to_just_before_a_crossing(rig));
  const auto crossings_before = rig.emulator->broadcasts_sent();
  rig.sink.arm(rig.own_driver_clock, kHold, false);
  ASSERT_TRUE(run_until_held(rig));
  ASSERT_EQ(rig.emulator->broadcasts_sent(), crossings_before + 1) << "the read held up was not the crossing's";
  ASSERT_TRUE(rig.clock.run_for(kHold));  // the emulator's clock catches up
  ASSERT_EQ(rig.own_driver_clock.now(), rig.clock.now());
  const Honesty h = honesty_after(rig, rig.clock.now_us());
  ASSERT_GE(h.degraded, 5);
  EXPECT_EQ(h.inside, h.degraded) << "poses after the hold-up lag the truth: the crossing was timed when acted on";
  EXPECT_EQ(rig.sink.errors, 0);
}

// The driver held up after a read and before the poses it publishes in the same loop: the
// port went unseen through the hold-up, and a crossing that came in it waits unread, so
// those poses must allow for it, as after a hold-up anywhere else.
TEST(LenzDriver, APortUnseenWhileTheDriverWorkedIsAllowedForInThePosesAfter) {
  Rig rig(Interface::Li101f, "held_before_publish", true);
  ASSERT_TRUE(run_to_just_before_a_crossing(rig, 100ms));
  const auto crossings_before = rig.emulator->broadcasts_sent();
  rig.sink.arm(rig.own_driver_clock, kHold, true);
  // A read as a sample is due: two steps before it is due, a feedback broadcast of a module
  // this layout does not watch, sent while the driver's clock stands so that it waits for
  // the driver's next look, two steps on at once. A terminal hands bytes over a little
  // later in real time, and the look may have come first: then again, a period on.
  for (int period = 0; !rig.sink.held() && period < 3; ++period) {
    const std::int64_t two_steps_us = std::chrono::microseconds(2 * kStep).count();
    while (rig.own_driver_clock.now_us() - rig.sink.last_pose_us() < kSamplePeriodUs - two_steps_us)
      ASSERT_TRUE(rig.run_both_for(kStep));
    rig.emulator->forge_feedback({90, 0x40});
    ASSERT_TRUE(rig.clock.run_for(2 * kStep));
    rig.own_driver_clock.advance(2 * kStep);
    ASSERT_TRUE(rig.own_driver_clock.settle());
  }
  ASSERT_TRUE(rig.sink.held()) << "no read of the forged broadcasts came as a sample was due";
  ASSERT_EQ(rig.emulator->broadcasts_sent(), crossings_before) << "the crossing came before the hold-up";
  ASSERT_TRUE(rig.clock.run_for(kHold));  // the emulator's clock catches up
  ASSERT_EQ(rig.own_driver_clock.now(), rig.clock.now());
  ASSERT_EQ(rig.emulator->broadcasts_sent(), crossings_before + 1) << "the crossing was not in the hold-up";
  const Honesty h = honesty_after(rig, rig.clock.now_us());
  ASSERT_GE(h.degraded, 5);
  EXPECT_EQ(h.inside, h.degraded) << "poses after the hold-up miss the truth: the port unseen in it was not allowed for";
  EXPECT_EQ(rig.sink.errors, 0);
}

TEST(LenzDriver, LiUsbPrefixesBothWays) {
  Rig rig(Interface::LiUsb, "liusb");
  ASSERT_TRUE(rig.clock.run_for(2s));
  const auto poses = rig.poses();
  const auto degraded = std::count_if(poses.begin(), poses.end(),
                                      [](const PoseSample& p) { return p.status == TrackingStatus::Degraded; });
  EXPECT_GT(degraded, 150);
  const auto raw = rig.raw();
  EXPECT_TRUE(contains(raw, {0xFF, 0xFE, 0x21, 0x24, 0x05}));        // request, prefixed
  EXPECT_TRUE(contains(raw, {0xFF, 0xFE, 0x62, 0x22, 0x00, 0x40}));  // reply
  EXPECT_TRUE(contains(raw, {0xFF, 0xFD}));                          // a feedback broadcast
  EXPECT_EQ(rig.sink.errors, 0);
  EXPECT_FALSE(rig.returned) << "a valid stream was failed: " << (rig.result ? "" : rig.result.error().message);
}

TEST(LenzDriver, PortClosedMidRunGoesLostAndResumesOnReopen) {
  Rig rig(Interface::Li101f, "unplug");
  ASSERT_TRUE(rig.clock.run_for(1500ms));
  const std::int64_t unplugged_us = rig.clock.now_us();
  rig.emulator->unplug();
  ASSERT_TRUE(rig.clock.run_for(2500ms));
  const std::int64_t replugged_us = rig.clock.now_us();
  rig.emulator->replug();
  ASSERT_TRUE(rig.clock.run_for(2000ms));
  const auto poses = rig.poses();
  const std::int64_t step_us = std::chrono::microseconds(kStep).count();
  const auto period_us = std::llround(1e6 / rig.config.rate_hz);
  const auto reconnect_us = std::llround(1e6 * rig.config.reconnect_s);

  for (const std::string vehicle : {"loco", "car1", "car2"}) {
    std::int64_t first_lost_us = -1, first_back_us = -1;
    bool degraded_before = false;
    for (const auto& p : poses) {
      if (p.sensor != vehicle) continue;
      if (p.measurement_time_us < unplugged_us) degraded_before |= p.status == TrackingStatus::Degraded;
      if (p.measurement_time_us >= unplugged_us && first_lost_us < 0 && p.status == TrackingStatus::Lost)
        first_lost_us = p.measurement_time_us;
      if (p.measurement_time_us >= replugged_us && first_back_us < 0 && p.status == TrackingStatus::Degraded)
        first_back_us = p.measurement_time_us;
      // While unplugged (after the first LOST) nothing but LOST.
      if (first_lost_us >= 0 && p.measurement_time_us > first_lost_us && p.measurement_time_us < replugged_us) {
        EXPECT_EQ(p.status, TrackingStatus::Lost) << vehicle;
      }
    }
    EXPECT_TRUE(degraded_before) << vehicle;
    ASSERT_GE(first_lost_us, 0) << vehicle << " never went LOST";
    // The emulator closes the terminal in the first step after unplug(), the driver sees
    // the hang-up in that step or the next, and the next sample due reports LOST.
    EXPECT_LE(first_lost_us - unplugged_us, 2 * step_us + period_us) << vehicle;
    ASSERT_GE(first_back_us, 0) << vehicle << " did not resume";
    // The driver tries the port every reconnect_s; the new terminal is there one step
    // after replug(), the startup requests and their answers take a step each way (two
    // if they cross a step), and the next sample due is tracking again.
    EXPECT_LE(first_back_us - replugged_us, reconnect_us + 4 * step_us + period_us) << vehicle;
    std::printf("%s: LOST %.3f s after the unplug, tracking again %.3f s after the replug\n", vehicle.c_str(),
                (first_lost_us - unplugged_us) * 1e-6, (first_back_us - replugged_us) * 1e-6);
  }
  EXPECT_GE(rig.sink.errors, 1);  // the disconnection is reported, the driver kept running
}

TEST(LenzDriver, MissingPortAtStartIsAClearError) {
  LenzConfig config;
  config.device = "train";
  config.port = "/dev/covtrack-no-such-li101f";
  config.layout = short_layout();
  auto driver = make_lenz_driver(config);
  test::CaptureSink sink;
  std::stop_source stop;
  const auto result = driver->run(sink, stop.get_token());
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("/dev/covtrack-no-such-li101f"), std::string::npos) << result.error().message;
}

// Random bytes keep the line busy (so it never looks silent) without a single status
// reply: the driver must end its run with "no valid frames for N s" once N seconds have
// passed, instead of counting errors forever with every vehicle LOST.
TEST(LenzDriver, LineOfPureNoiseFailsWithNoValidFrames) {
  auto pty = serial::PseudoTerminal::create(::testing::TempDir() + "/covtrack_lenz_noise_" +
                                            std::to_string(::getpid()));
  ASSERT_TRUE(pty) << pty.error().message;
  LenzConfig config;
  config.device = "train";
  config.port = pty->device_path();
  config.layout = short_layout();
  config.keepalive_s = 0.2;
  config.link_timeout_s = 1.0;
  config.no_valid_frames_s = 1.0;
  test::ManualClock clock{kStep};
  auto driver = make_lenz_driver(config, clock);
  test::CaptureSink sink;
  std::promise<Result<void>> ended;
  auto result = ended.get_future();
  clock.join();
  std::jthread driver_thread([&](std::stop_token stop) {
    ended.set_value(driver->run(sink, stop));
    clock.leave();
  });
  ASSERT_TRUE(clock.settle()) << "the driver did not start";

  // 100 bytes a 5 ms step, about 20 kB/s: ten times what an LI101F at 19200 baud can
  // send; the driver's requests are drained so that its writes never block.
  std::mt19937 rng(22);
  std::uint8_t noise[100], drained[256];
  std::uint64_t noise_bytes = 0;
  while (result.wait_for(0s) != std::future_status::ready && clock.elapsed_s() < 20) {
    while (pty->read_some(drained, 0ms).value_or(0) > 0) {}
    for (auto& b : noise) b = static_cast<std::uint8_t>(rng());
    noise_bytes += pty->write(noise).value_or(0);
    ASSERT_TRUE(clock.run_for(kStep));
  }
  ASSERT_EQ(result.wait_for(0s), std::future_status::ready) << "the driver never failed on 20 s of noise";
  const double took_s = clock.elapsed_s();
  const auto outcome = result.get();
  ASSERT_FALSE(outcome) << "the driver stopped on its own without an error";
  const std::string& message = outcome.error().message;
  std::printf("%llu noise bytes, %d errors counted, failed after %.2f s: %s\n",
              static_cast<unsigned long long>(noise_bytes), sink.errors, took_s, message.c_str());
  EXPECT_NE(message.find("no valid frames for 1.0 s"), std::string::npos) << message;
  EXPECT_NE(message.find(config.port), std::string::npos) << message;
  // In the step that reaches the limit (the driver looks at the clock in every step).
  EXPECT_GE(took_s, config.no_valid_frames_s);
  EXPECT_LE(took_s, config.no_valid_frames_s + std::chrono::duration<double>(kStep).count());
  EXPECT_GT(sink.errors, 10);  // the noise's bad frames were counted on the way
  std::lock_guard lock(sink.m);
  ASSERT_FALSE(sink.poses.empty());
  EXPECT_EQ(sink.poses.back().status, TrackingStatus::Lost) << "vehicles left with a pose while the device fails";
}
