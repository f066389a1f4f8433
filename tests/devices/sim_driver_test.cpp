// The simulated tracker's covariance is honest: NEES of its reports against its own
// truth has the chi-square(6) mean. The driver runs on simulated time (manual_clock.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numeric>
#include <thread>

#include "capture_sink.hpp"
#include "covtrack/devices/sim/sim_driver.hpp"
#include "manual_clock.hpp"

using namespace covtrack;

namespace {

sim::SimConfig read(const std::string& toml_text, ConfigErrors& errors) {
  static toml::table table;  // the reader keeps a reference for the duration of the call
  table = toml::parse(std::string_view(toml_text), std::string_view("test.toml"));
  TableReader r(table, "devices.t", sim::sim_device_spec(), "test.toml", errors);
  return sim::read_sim_config(r, "t");
}

sim::SimConfig read_ok(const std::string& toml_text) {
  ConfigErrors errors;
  auto c = read(toml_text, errors);
  EXPECT_TRUE(errors.empty()) << errors.joined();
  return c;
}

// Runs the driver on simulated time until it has produced at least `samples` poses, or
// returned. The clock's steps (1 ms) stay under the driver's backlog limit of 10
// periods at these rates, so that no tick is skipped as if the machine had stalled.
Result<void> run_until(test::CaptureSink& sink, const sim::SimConfig& config, std::size_t samples) {
  test::ManualClock clock(std::chrono::milliseconds(1));
  auto driver = sim::make_sim_driver(config, 0, clock);
  std::stop_source stop;
  std::atomic<bool> returned = false;
  Result<void> result;
  clock.join();
  std::thread t([&] {
    result = driver->run(sink, stop.get_token());
    returned = true;
    clock.leave();
  });
  EXPECT_TRUE(clock.run_until(
      [&] {
        std::lock_guard l(sink.m);
        return returned || sink.poses.size() >= samples;
      },
      std::chrono::seconds(30)));
  stop.request_stop();
  t.join();
  return result;
}

// NEES of every OK report against the truth of the same time.
std::vector<double> nees_values(const test::CaptureSink& sink, const Mat6& claimed) {
  const Mat6 info = claimed.inverse();
  std::vector<double> out;
  for (std::size_t i = 0; i < sink.poses.size(); ++i) {
    const auto& p = sink.poses[i];
    const auto& t = sink.truths[i];
    EXPECT_EQ(p.sensor, t.sensor);
    EXPECT_EQ(p.measurement_time_us, t.measurement_time_us);
    if (p.status != TrackingStatus::Ok) continue;
    const Vec6 e = boxminus(t.T_parent_child, p.T_parent_child);  // T_true = T_est Exp(e)
    out.push_back(e.dot(info * e));
  }
  return out;
}

struct Nees {
  double mean = 0;
  std::size_t count = 0;
};

Nees nees(const test::CaptureSink& sink, const Mat6& claimed) {
  const auto v = nees_values(sink, claimed);
  return {std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()), v.size()};
}

// Two-sided 99% bounds of the mean of n chi-square(6) draws (normal approximation,
// accurate for n in the thousands): 6 +- 2.576 sqrt(12 / n).
bool inside_99(const Nees& n) {
  return std::abs(n.mean - 6.0) <= 2.576 * std::sqrt(12.0 / static_cast<double>(n.count));
}

constexpr double kChi2_6_99 = 16.812;

double fraction_above(const test::CaptureSink& sink, const Mat6& claimed, double threshold) {
  const auto v = nees_values(sink, claimed);
  return static_cast<double>(std::count_if(v.begin(), v.end(), [&](double x) { return x > threshold; })) /
         static_cast<double>(v.size());
}

}  // namespace

TEST(SimDriver, NeesOfDiagonalCovarianceIsChiSquare6) {
  const auto config = read_ok(R"(
    type = "sim"
    sensors = ["a", "b"]
    rate_hz = 5000
    sigma_m = [0.001, 0.002, 0.003]
    sigma_rad = [0.01, 0.02, 0.005]
    seed = 11
    [motion]
    kind = "circle"
  )");
  test::CaptureSink sink;
  ASSERT_TRUE(run_until(sink, config, 4000));
  const Nees n = nees(sink, config.covariance);
  ASSERT_GE(n.count, 2000u);
  EXPECT_TRUE(inside_99(n)) << "mean NEES " << n.mean << " over " << n.count;
  // The same data judged with a covariance twice too large must fail the bound: the
  // test can tell an honest covariance from a dishonest one.
  EXPECT_FALSE(inside_99(nees(sink, 2.0 * config.covariance)));
}

TEST(SimDriver, NeesOfFullCorrelatedCovarianceIsChiSquare6) {
  const auto config = read_ok(R"(
    type = "sim"
    sensor_count = 3
    rate_hz = 3000
    covariance = [
      1.0e-5, 4.0e-6, 0, 1.0e-6, 0, 0,
      4.0e-6, 1.0e-5, 0, 0, 0, 0,
      0, 0, 4.0e-5, 0, 0, 0,
      1.0e-6, 0, 0, 3.0e-5, 0, 0,
      0, 0, 0, 0, 3.0e-5, 1.0e-5,
      0, 0, 0, 0, 1.0e-5, 1.0e-4]
    [motion]
    kind = "random_walk"
  )");
  test::CaptureSink sink;
  ASSERT_TRUE(run_until(sink, config, 6000));
  const Nees n = nees(sink, config.covariance);
  ASSERT_GE(n.count, 2000u);
  EXPECT_TRUE(inside_99(n)) << "mean NEES " << n.mean << " over " << n.count;
  // The tail too: about 1% of NEES values above the chi-square(6) 99% quantile.
  EXPECT_NEAR(fraction_above(sink, config.covariance, kChi2_6_99), 0.01, 0.006);
  // A covariance 1.5x too small is caught.
  EXPECT_FALSE(inside_99(nees(sink, config.covariance / 1.5)));
}

TEST(SimDriver, DropoutsReportLostWithInfiniteUncertainty) {
  const auto config = read_ok(R"(
    type = "sim"
    sensor_count = 1
    rate_hz = 1000
    sigma_m = [0.001, 0.001, 0.001]
    sigma_rad = [0.001, 0.001, 0.001]
    dropout_every_s = 0.2
    dropout_duration_s = 0.05
  )");
  test::CaptureSink sink;
  ASSERT_TRUE(run_until(sink, config, 1000));
  std::size_t lost = 0;
  for (const auto& p : sink.poses)
    lost += p.status == TrackingStatus::Lost;  // the sink checks each one's covariance
  const double fraction = static_cast<double>(lost) / static_cast<double>(sink.poses.size());
  EXPECT_NEAR(fraction, 0.25, 0.05);
}

TEST(SimDriver, InjectedFailureEndsTheRunWithAnError) {
  const auto config = read_ok(R"(
    type = "sim"
    sensor_count = 1
    rate_hz = 1000
    sigma_m = [0.001, 0.001, 0.001]
    sigma_rad = [0.001, 0.001, 0.001]
    inject_failure_every_s = 0.05
  )");
  test::CaptureSink sink;
  const auto result = run_until(sink, config, 1'000'000);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("injected failure"), std::string::npos);
  EXPECT_NEAR(static_cast<double>(sink.poses.size()), 50, 2);
}

TEST(SimDriver, EveryMotionStaysNearItsCentre) {
  for (const char* kind : {"static", "circle", "figure_eight", "random_walk", "waypoints"}) {
    const auto config = read_ok(std::string(R"(
      type = "sim"
      sensor_count = 1
      rate_hz = 2000
      sigma_m = [0.001, 0.001, 0.001]
      sigma_rad = [0.001, 0.001, 0.001]
      [motion]
      center_m = [1, 2, 3]
      radius_m = 0.5
      waypoints_m = [0.5, 2, 3,  1.5, 2, 3,  1, 2.5, 3]
      kind = ")") + kind + "\"\n");
    test::CaptureSink sink;
    ASSERT_TRUE(run_until(sink, config, 400));
    ASSERT_GE(sink.truths.size(), 400u);
    for (const auto& t : sink.truths) {
      const double d = (t.T_parent_child.translation() - Vec3(1, 2, 3)).norm();
      EXPECT_LE(d, 0.5 * std::sqrt(3.0) + 1e-9) << kind;
    }
    // It moves (but for static) and it moves continuously.
    const double travelled =
        (sink.truths.back().T_parent_child.translation() - sink.truths.front().T_parent_child.translation()).norm();
    if (std::string(kind) == "static") EXPECT_EQ(travelled, 0.0);
    else EXPECT_GT(travelled, 1e-4) << kind;
  }
}

TEST(SimConfig, ConflictingOrMissingNoiseIsReported) {
  ConfigErrors errors;
  read(R"(
    type = "sim"
    sensor_count = 1
    sigma_m = [0.001, 0.001, 0.001]
    sigma_rad = [0.001, 0.001, 0.001]
    covariance = [1,0,0,0,0,0, 0,1,0,0,0,0, 0,0,1,0,0,0, 0,0,0,1,0,0, 0,0,0,0,1,0, 0,0,0,0,0,1]
  )", errors);
  ASSERT_EQ(errors.list().size(), 1u) << errors.joined();
  EXPECT_NE(errors.list()[0].find("test.toml:6:"), std::string::npos) << errors.list()[0];

  ConfigErrors indefinite;
  read(R"(
    type = "sim"
    sensor_count = 1
    covariance = [1,2,0,0,0,0, 2,1,0,0,0,0, 0,0,1,0,0,0, 0,0,0,1,0,0, 0,0,0,0,1,0, 0,0,0,0,0,1]
  )", indefinite);
  ASSERT_EQ(indefinite.list().size(), 1u) << indefinite.joined();
  EXPECT_NE(indefinite.list()[0].find("not positive semi-definite"), std::string::npos);
}
