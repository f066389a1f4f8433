// The serial 6-DOF driver against its emulators over real pseudo-terminals: the
// configuration sequence per protocol, NEES of the reported covariance against the
// emulator's truth, trouble flags, units, and the port going away and coming back.
// Driver and emulator run on a simulated clock (manual_clock.hpp) wherever they stream:
// a loaded machine cannot make a LOST report late or stall the emulator into a burst that
// the motion gate would see as a jump, and thousands of records take a fraction of a
// second instead of their real duration.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <thread>

#include "capture_sink.hpp"
#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"
#include "covtrack/emulators/serial6dof/emulator.hpp"
#include "device_model.hpp"
#include "manual_clock.hpp"
#include "support/one_percent_bar.hpp"

using namespace covtrack;
using namespace covtrack::serial6dof;
using namespace std::chrono_literals;

namespace {

std::string link_path(const std::string& name) {
  return ::testing::TempDir() + "/covtrack_6dof_" + name + "_" + std::to_string(::getpid());
}

struct Rig {
  std::unique_ptr<emulate6dof::Emulator> emulator;
  std::map<std::string, Pose> truth;  // the emulated receivers do not move
};

// `clock`: the emulator runs on it (and joins it), else on the real clock.
Rig make_rig(Model model, const std::vector<int>& stations, const std::string& name,
             double trouble_every_s = 0, double rate_hz = 0,
             const std::function<void(emulate6dof::EmulatorConfig&)>& tweak = {},
             test::ManualClock* clock = nullptr) {
  emulate6dof::EmulatorConfig ec;
  ec.model = model;
  ec.link_path = link_path(name);
  ec.stations = emulate6dof::default_stations(stations);
  ec.reset_time_s = 0.2;
  ec.rate_hz = rate_hz;
  ec.trouble_every_s = trouble_every_s;
  ec.seed = 7 + static_cast<std::uint64_t>(model);  // each model its own noise
  if (tweak) tweak(ec);
  auto e = clock ? emulate6dof::Emulator::create(ec, *clock) : emulate6dof::Emulator::create(ec);
  EXPECT_TRUE(e) << e.error().message;
  Rig rig{std::move(*e), {}};
  for (const auto& s : ec.stations) rig.truth[s.name] = s.T_source_receiver;
  if (clock) clock->join();
  rig.emulator->start(nullptr);
  return rig;
}

Serial6dofConfig driver_config(Model model, const std::vector<int>& stations, const std::string& port,
                               double rate_hz = 0) {
  Serial6dofConfig c;
  c.device = "dut";
  c.model = model;
  c.port = port;
  for (int s : stations) c.stations.push_back({s, "st" + std::to_string(s), std::nullopt});
  c.rate_hz = rate_hz > 0 ? rate_hz : station_rate_hz(model_spec(model), static_cast<int>(stations.size()));
  c.reset_time_s = 0.25;
  c.reply_timeout_s = 1.0;
  return c;
}

// Runs the driver until `wanted` non-LOST poses arrived (or 30 s passed), on `clock`
// (which the driver joins) if given, else on the real clock.
Result<void> run_for_samples(test::CaptureSink& sink, const Serial6dofConfig& c, std::size_t wanted,
                             std::uint64_t run_index = 0, test::ManualClock* clock = nullptr) {
  auto driver = clock ? make_serial6dof_driver(c, run_index, *clock) : make_serial6dof_driver(c, run_index);
  std::stop_source stop;
  Result<void> result;
  std::atomic<bool> done = false;
  if (clock) clock->join();
  std::thread t([&] {
    result = driver->run(sink, stop.get_token());
    done = true;
    if (clock) clock->leave();
  });
  const auto enough = [&] {
    std::lock_guard l(sink.m);
    std::size_t good = 0;
    for (const auto& p : sink.poses) good += p.status != TrackingStatus::Lost;
    return done || good >= wanted;
  };
  if (clock) {
    clock->run_until(enough, 30s);
  } else {
    for (int i = 0; i < 3000 && !enough(); ++i) std::this_thread::sleep_for(10ms);
  }
  stop.request_stop();
  t.join();
  return result;
}

// A first run of the driver on `clock`, in its own thread, until it returns or the test
// ends; the constructor returns once the emulator has streamed 50 records to it.
struct ClockedRun {
  ClockedRun(const Serial6dofConfig& c, test::ManualClock& clock, const emulate6dof::Emulator& emulator)
      : driver(make_serial6dof_driver(c, 0, clock)) {
    clock.join();
    thread = std::jthread([this, &clock](std::stop_token stop) {
      result = driver->run(sink, stop);
      returned = true;
      clock.leave();
    });
    EXPECT_TRUE(clock.run_until([&] { return emulator.records_sent() >= 50; }, 30s));
  }

  std::unique_ptr<Driver> driver;
  test::CaptureSink sink;
  Result<void> result;
  std::atomic<bool> returned = false;
  std::jthread thread;
};

struct NeesSummary {
  double mean = 0;
  int n = 0, degraded = 0;
  int outside = 0;  // beyond the 99.9 % quantile of chi-square(6)
  double largest = 0;
};

NeesSummary nees(const test::CaptureSink& sink, const Rig& rig) {
  NeesSummary s;
  double sum = 0;
  for (const auto& p : sink.poses) {
    if (p.status == TrackingStatus::Lost) continue;
    const Vec6 e = boxminus(rig.truth.at(p.sensor), p.T_parent_child);  // T_true = T_est Exp(e)
    const double nees = e.dot(p.covariance.inverse() * e);
    sum += nees;
    s.outside += nees > 22.458;
    s.largest = std::max(s.largest, nees);
    ++s.n;
    s.degraded += p.status == TrackingStatus::Degraded;
  }
  s.mean = s.n ? sum / s.n : 0;
  return s;
}

// 99.9 % two-sided bound on the mean of n chi-square(6) values (variance 12 each).
double nees_bound(int n) { return 3.29 * std::sqrt(12.0 / n); }
constexpr double kGateShift = 0.15;

class Serial6dofDriverNees : public ::testing::TestWithParam<Model> {};

}  // namespace

TEST_P(Serial6dofDriverNees, ReportedCovarianceMatchesTheErrorsAgainstTruth) {
  const Model model = GetParam();
  const std::vector<int> stations = {1, 2};
  const std::string name = std::string(model_spec(model).name);
  const double rate_hz = 200;  // faster than most of these units, to keep the test short
  test::ManualClock clock;
  Rig rig = make_rig(model, stations, name, /*trouble_every_s=*/0.05, rate_hz, {}, &clock);
  test::CaptureSink sink;
  auto result =
      run_for_samples(sink, driver_config(model, stations, rig.emulator->device_path(), rate_hz), 1500, 0, &clock);
  EXPECT_TRUE(result) << result.error().message;
  const auto s = nees(sink, rig);
  ASSERT_GE(s.n, 1500) << "errors: " << sink.errors;
  // The plausibility gate widens the covariance of the 2.5 % most surprising records,
  // which lowers a clean stream's mean NEES by about 0.1: the band is shifted by that.
  EXPECT_GT(s.mean, 6.0 - nees_bound(s.n) - kGateShift) << name << " over " << s.n << " poses";
  EXPECT_LT(s.mean, 6.0 + nees_bound(s.n)) << name << " over " << s.n << " poses";
  if (model != Model::Flock) {
    EXPECT_GT(s.degraded, 10) << "trouble flags must give DEGRADED";
  }
  for (const auto& p : sink.poses) EXPECT_EQ(p.parent_frame, "world");
  EXPECT_EQ(sink.errors, 0);
  std::cout << "[ NEES ] " << name << ": mean " << s.mean << " over " << s.n << " poses ("
            << s.degraded << " degraded), 99.9% band 6 +- " << nees_bound(s.n) << "\n";
}

INSTANTIATE_TEST_SUITE_P(AllModels, Serial6dofDriverNees,
                         ::testing::Values(Model::Fastrak, Model::Is900, Model::Liberty,
                                           Model::Patriot, Model::Flock),
                         [](const auto& info) { return std::string(model_spec(info.param).name); });

// A noisy serial line (bits flipped, bytes dropped and doubled in what the unit
// streams, at the rate of a bad cable: about one record in four touched) must not turn
// into confident wrong poses: no more of what is published may lie outside its own
// 99.9 % region than an honest covariance puts there on a clean line (at most the count
// a 0.1 % rate exceeds in 1 % of runs: a bar of 0.1 % of n, its expected count, failed a
// CI run with 7 of 6,000), and none far out: NEES 100 is 3e-19 of an honest chi-square(6)'s
// mass, where corrupt records once made poses over 100 sigma off (the largest seen here,
// the line noise and the machine's load varied: 52).
class Serial6dofLineNoise : public ::testing::TestWithParam<Model> {};

TEST_P(Serial6dofLineNoise, CorruptRecordsNeverBecomeConfidentPoses) {
  const Model model = GetParam();
  const std::string name = "noise_" + std::string(model_spec(model).name);
  const double rate_hz = 240;
  test::ManualClock clock;
  Rig rig = make_rig(
      model, {1, 2}, name, 0, rate_hz,
      [](emulate6dof::EmulatorConfig& c) {
        c.bit_flips_per_s = 120;
        c.bytes_dropped_per_s = 10;
        c.bytes_duplicated_per_s = 10;
      },
      &clock);
  test::CaptureSink sink;
  (void)run_for_samples(sink, driver_config(model, {1, 2}, rig.emulator->device_path(), rate_hz), 6000, 0, &clock);
  const auto s = nees(sink, rig);
  std::cout << "[ line noise ] " << model_spec(model).name << ": " << rig.emulator->noise_events()
            << " noise events, " << s.n << " poses published (" << s.degraded << " degraded), "
            << sink.errors << " records dropped, " << s.outside << " outside 99.9%, mean NEES " << s.mean
            << ", largest " << s.largest << "\n";
  ASSERT_GE(s.n, 5000);
  EXPECT_GT(rig.emulator->noise_events(), 1000u) << "the line must be noisy for the test to mean anything";
  EXPECT_GT(sink.errors, 0) << "some records must be dropped";
  EXPECT_LE(s.outside, test::most_outside(s.n, 0.001));
  EXPECT_LT(s.largest, 100.0);
}

TEST(Serial6dofDriver, TheGateDropsNothingFromACleanMovingStream) {
  // Receivers swaying like a hand (0.15 m and 0.4 rad at 0.7-1.2 Hz: up to 1.1 m/s).
  const double rate_hz = 240;
  test::ManualClock clock;
  Rig rig = make_rig(
      Model::Liberty, {1, 2}, "sway", 0, rate_hz,
      [](emulate6dof::EmulatorConfig& c) {
        c.sway_m = 0.15;
        c.sway_rad = 0.4;
        c.sway_hz = 0.7;
      },
      &clock);
  test::CaptureSink sink;
  (void)run_for_samples(sink, driver_config(Model::Liberty, {1, 2}, rig.emulator->device_path(), rate_hz), 3000, 0,
                        &clock);
  int published = 0, degraded = 0;
  for (const auto& p : sink.poses) {
    published += p.status != TrackingStatus::Lost;
    degraded += p.status == TrackingStatus::Degraded;
  }
  std::cout << "[ sway ] " << published << " poses, " << degraded << " degraded, " << sink.errors << " dropped\n";
  ASSERT_GE(published, 3000);
  EXPECT_EQ(sink.errors, 0) << "a clean stream loses nothing to the gate";
  EXPECT_LE(degraded, 0.03 * published) << "motion the prediction did not foresee: widened, rarely DEGRADED";
}

INSTANTIATE_TEST_SUITE_P(EachProtocol, Serial6dofLineNoise,
                         ::testing::Values(Model::Fastrak, Model::Liberty, Model::Flock),
                         [](const auto& info) { return std::string(model_spec(info.param).name); });

TEST(Serial6dofDriver, InchesAreConfirmedAndConvertedToo) {
  for (Model model : {Model::Fastrak, Model::Liberty}) {
    test::ManualClock clock;
    Rig rig = make_rig(model, {1}, std::string("inches_") + std::string(model_spec(model).name), 0, 0, {}, &clock);
    auto c = driver_config(model, {1}, rig.emulator->device_path());
    c.units = Units::Inches;
    test::CaptureSink sink;
    EXPECT_TRUE(run_for_samples(sink, c, 300, 0, &clock));
    const auto s = nees(sink, rig);
    ASSERT_GE(s.n, 300);
    EXPECT_NEAR(s.mean, 6.0, nees_bound(s.n)) << "a units mix-up would be 2.54x off";
  }
}

TEST(Serial6dofDriver, FlockScalingMismatchIsAClearError) {
  Rig rig = make_rig(Model::Flock, {1}, "flock_scale");
  auto c = driver_config(Model::Flock, {1}, rig.emulator->device_path());
  c.flock_position_scale_in = 72;  // the emulated bird says 36
  test::CaptureSink sink;
  auto result = run_for_samples(sink, c, 1);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("units not confirmed"), std::string::npos) << result.error().message;
}

TEST(Serial6dofDriver, MissingPortIsAClearErrorNotAHang) {
  auto c = driver_config(Model::Fastrak, {1}, "/dev/covtrack-no-such-tracker");
  test::CaptureSink sink;
  const auto t0 = std::chrono::steady_clock::now();
  auto result = make_serial6dof_driver(c, 0)->run(sink, std::stop_source().get_token());
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("/dev/covtrack-no-such-tracker"), std::string::npos);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s);
}

TEST(Serial6dofDriver, SilentPortIsAClearError) {
  emulate6dof::EmulatorConfig ec;  // a pseudo-terminal with nothing answering behind it
  ec.link_path = link_path("silent");
  ec.stations = emulate6dof::default_stations({1});
  auto e = emulate6dof::Emulator::create(ec);
  ASSERT_TRUE(e);  // not started: nobody answers
  auto c = driver_config(Model::Liberty, {1}, (*e)->device_path());
  c.reply_timeout_s = 0.2;
  test::CaptureSink sink;
  auto result = make_serial6dof_driver(c, 0)->run(sink, std::stop_source().get_token());
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("no answer"), std::string::npos) << result.error().message;
}

TEST(Serial6dofDriver, UnpluggedPortGivesLostWithinTwoPeriodsThenRecovers) {
  const double rate_hz = 50;
  test::ManualClock clock;
  Rig rig = make_rig(Model::Liberty, {1}, "unplug", 0, rate_hz, {}, &clock);
  const auto c = driver_config(Model::Liberty, {1}, rig.emulator->device_path(), rate_hz);
  ClockedRun run(c, clock, *rig.emulator);
  const std::int64_t unplugged_us = clock.now_us();
  rig.emulator->unplug();
  ASSERT_TRUE(clock.run_until([&] { return run.returned.load(); }, 30s));  // the port is gone: it fails
  run.thread.join();
  const auto& result = run.result;
  const auto& sink = run.sink;
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("LOST"), std::string::npos) << result.error().message;
  std::int64_t lost_us = 0;
  for (const auto& p : sink.poses)
    if (p.status == TrackingStatus::Lost) { lost_us = p.measurement_time_us; break; }
  ASSERT_GT(lost_us, 0) << "no LOST report";
  EXPECT_LT(lost_us - unplugged_us, 2 * 1e6 / rate_hz) << "LOST later than two report periods";
  EXPECT_TRUE(std::isinf(sink.poses.back().covariance(0, 0)));

  // Back again: the restarted driver (run 1, which resets the unit) streams again.
  rig.emulator->replug();
  ASSERT_TRUE(clock.run_until([&] { return rig.emulator->plugged(); }, 30s));
  test::CaptureSink after;
  const Result<void> back = run_for_samples(after, c, 100, 1, &clock);
  EXPECT_TRUE(back) << back.error().message;
  EXPECT_GE(nees(after, rig).n, 100) << "errors: " << after.errors;
  EXPECT_GE(rig.emulator->resets(), 1u);
}

TEST(Serial6dofConfig, ErrorsNameTheKeyAndLine) {
  static toml::table table;  // the reader keeps a reference for the duration of the call
  table = toml::parse(std::string_view(
                          "type = \"fastrak\"\nport = \"/dev/x\"\nunits = \"mm\"\n"
                          "output_items = [\"timestamp\"]\n[[stations]]\nnumber = 2\n[[stations]]\nnumber = 2\n"),
                      std::string_view("t.toml"));
  ConfigErrors errors;
  TableReader r(table, "devices.f", serial6dof_device_spec(Protocol::Fastrak), "t.toml", errors);
  (void)read_serial6dof_config(r, "f", Protocol::Fastrak);
  const std::string all = errors.joined();
  EXPECT_NE(all.find("t.toml:3:9: devices.f.units"), std::string::npos) << all;
  EXPECT_NE(all.find("need model = \"is900\""), std::string::npos) << all;
  EXPECT_NE(all.find("station 2 is listed twice"), std::string::npos) << all;
}

TEST(Serial6dofConfig, DefaultsComeFromTheModel) {
  static toml::table table;
  table = toml::parse(std::string_view("type = \"fastrak\"\nport = \"/dev/x\"\nmodel = \"is900\"\n"),
                      std::string_view("t.toml"));
  ConfigErrors errors;
  TableReader r(table, "devices.f", serial6dof_device_spec(Protocol::Fastrak), "t.toml", errors);
  const auto c = read_serial6dof_config(r, "f", Protocol::Fastrak);
  EXPECT_TRUE(errors.empty()) << errors.joined();
  EXPECT_EQ(c.model, Model::Is900);
  EXPECT_EQ(c.reset_time_s, 20);
  ASSERT_EQ(c.stations.size(), 1u);
  EXPECT_EQ(c.stations[0].name, "st1");
  EXPECT_FALSE(c.stations[0].covariance.has_value());  // the model's accuracy applies
}

TEST(Serial6dofDriver, HungUnitGivesLostThenTheRestartResetsIt) {
  const double rate_hz = 50;
  test::ManualClock clock;
  Rig rig = make_rig(Model::Fastrak, {1, 2}, "hung", 0, rate_hz, {}, &clock);
  const auto c = driver_config(Model::Fastrak, {1, 2}, rig.emulator->device_path(), rate_hz);
  ClockedRun run(c, clock, *rig.emulator);
  const std::int64_t hung_us = clock.now_us();
  rig.emulator->hang();
  // The driver gives up on a silent unit by itself (after 1 s).
  ASSERT_TRUE(clock.run_until([&] { return run.returned.load(); }, 30s));
  run.thread.join();
  const auto& result = run.result;
  const auto& sink = run.sink;
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("no records"), std::string::npos) << result.error().message;
  std::map<std::string, std::int64_t> first_lost_us;
  for (const auto& p : sink.poses)
    if (p.status == TrackingStatus::Lost && !first_lost_us.count(p.sensor)) first_lost_us[p.sensor] = p.measurement_time_us;
  ASSERT_EQ(first_lost_us.size(), 2u) << "both stations must be reported LOST";
  for (const auto& [sensor, t_us] : first_lost_us)
    EXPECT_LT(t_us - hung_us, 2 * 1e6 / rate_hz) << sensor << ": watchdog later than 2 periods";

  // The restart (run 1) resets the unit, which cures it.
  const auto resets_before = rig.emulator->resets();
  test::CaptureSink after;
  EXPECT_TRUE(run_for_samples(after, c, 100, 1, &clock));
  EXPECT_GT(rig.emulator->resets(), resets_before);
  EXPECT_FALSE(rig.emulator->hung());
  EXPECT_GE(nees(after, rig).n, 100);
}
