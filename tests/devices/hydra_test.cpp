// Razer Hydra: the report parser on reports built from the documented format, the
// hemisphere resolution, the mode-switch feature reports, the plausibility gate on
// reports with magnetic glitches, and a clear error without a device.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <random>

#include "capture_sink.hpp"
#include "covtrack/devices/hydra/hydra_driver.hpp"
#include "hydra_report.hpp"
#include "hydra_stream.hpp"

using namespace covtrack;
using namespace covtrack::hydra;

TEST(HydraReport, HandBuiltBytesFromTheDocumentedLayout) {
  std::array<std::uint8_t, kReportSize> b{};
  // Controller 0 at byte 8: x = -100 mm, y = 250 mm, z = 1 mm; q = (w 0.5, x 0.5, y 0.5, z 0.5)
  const std::uint8_t c0[] = {0x9C, 0xFF, 0xFA, 0x00, 0x01, 0x00,  0x00, 0x40, 0x00, 0x40,
                             0x00, 0x40, 0x00, 0x40, 0x21,  0x00, 0xC0, 0x00, 0x40, 0xFF};
  std::copy(std::begin(c0), std::end(c0), b.begin() + 8);
  b[30 + 6] = 0xFF;  // controller 1: identity quaternion (w = 32767/32768)
  b[30 + 7] = 0x7F;
  auto r = parse_hydra_report(b);
  ASSERT_TRUE(r) << r.error().message;
  const auto& c = r->controllers[0];
  EXPECT_NEAR(c.position_m.x(), -0.100, 1e-12);
  EXPECT_NEAR(c.position_m.y(), 0.250, 1e-12);
  EXPECT_NEAR(c.position_m.z(), 0.001, 1e-12);
  EXPECT_NEAR(c.orientation.w(), 0.5, 1e-12);
  EXPECT_NEAR(c.orientation.z(), 0.5, 1e-12);
  EXPECT_EQ(c.buttons, 0x21);             // bumper + start
  EXPECT_NEAR(c.joystick_x, -0.5, 1e-12);  // 0xC000
  EXPECT_NEAR(c.joystick_y, 0.5, 1e-12);   // 0x4000
  EXPECT_NEAR(c.trigger, 1.0, 1e-12);
  EXPECT_NEAR(r->controllers[1].orientation.w(), 1.0, 1e-4);
}

TEST(HydraReport, RoundTripOfBothControllers) {
  HydraReport in;
  in.controllers[0].position_m = Vec3(-0.2, 0.05, -0.3);
  in.controllers[0].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.8, Vec3(0, 1, 1).normalized()));
  in.controllers[1].position_m = Vec3(0.25, -0.1, 0.4);
  in.controllers[1].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(-2.0, Vec3(1, 0, 0)));
  in.controllers[1].trigger = 0.5;
  auto out = parse_hydra_report(build_hydra_report(in));
  ASSERT_TRUE(out);
  for (int i = 0; i < 2; ++i) {
    EXPECT_LT((out->controllers[i].position_m - in.controllers[i].position_m).norm(), 1e-3);  // 1 mm steps
    EXPECT_LT((out->controllers[i].orientation.coeffs() - in.controllers[i].orientation.coeffs()).norm(), 1e-4);
  }
  EXPECT_NEAR(out->controllers[1].trigger, 0.5, 1.0 / 255);
}

TEST(HydraReport, WrongSizeAndBadQuaternionAreErrors) {
  std::vector<std::uint8_t> short_report(40);
  auto r = parse_hydra_report(short_report);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("40 bytes"), std::string::npos);
  std::array<std::uint8_t, kReportSize> zeros{};  // quaternion of norm 0
  EXPECT_FALSE(parse_hydra_report(zeros));
}

TEST(HydraReport, ModeSwitchFeatureReports) {
  const auto motion = motion_mode_feature_report();
  const auto gamepad = gamepad_mode_feature_report();
  EXPECT_EQ(motion[0], 0);  // report id
  EXPECT_EQ(motion[9], 0x03);
  EXPECT_EQ(motion[89], 0x06);
  EXPECT_EQ(gamepad[9], 0x00);
  EXPECT_EQ(gamepad[89], 0x05);
}

TEST(HemisphereTracker, StartsLeftRightThenFollowsContinuity) {
  HemisphereTracker h;
  // The left controller reported on the right: mirrored to the left at the start.
  EXPECT_TRUE(h.resolve(0, Vec3(0.1, 0.0, 0.2)).isApprox(Vec3(-0.1, 0.0, -0.2)));
  EXPECT_TRUE(h.resolve(1, Vec3(0.1, 0.0, 0.2)).isApprox(Vec3(0.1, 0.0, 0.2)));
  // The controller moves across x = 0 smoothly while the device flips the sign: the
  // continuous path is kept.
  EXPECT_TRUE(h.resolve(0, Vec3(0.09, 0.0, 0.21)).isApprox(Vec3(-0.09, 0.0, -0.21)));
  EXPECT_TRUE(h.resolve(0, Vec3(-0.08, 0.0, -0.22)).isApprox(Vec3(-0.08, 0.0, -0.22)));
}

TEST(HydraDriver, AbsentDeviceIsAClearErrorNotAHang) {
  HydraConfig c;
  c.device = "hydra";
  c.hid_path = "/dev/covtrack-no-such-hidraw";
  c.covariance = hydra_default_covariance();
  test::CaptureSink sink;
  const auto t0 = std::chrono::steady_clock::now();
  auto r = make_hydra_driver(c)->run(sink, std::stop_source().get_token());
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("Razer Hydra"), std::string::npos) << r.error().message;
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
  // With no path given, it searches and says it is not found (no Hydra in the test machine).
  c.hid_path.clear();
  auto search = make_hydra_driver(c)->run(sink, std::stop_source().get_token());
  if (!search) {
    EXPECT_NE(search.error().message.find("Razer Hydra"), std::string::npos);
  }
}

TEST(HydraDriver, DefaultCovarianceIsTheStatedAccuracy) {
  const Mat6 c = hydra_default_covariance();
  EXPECT_NEAR(std::sqrt(c(0, 0)), 1e-3, 1e-12);
  EXPECT_NEAR(std::sqrt(c(5, 5)) * 180 / 3.141592653589793, 1.0, 1e-9);
  EXPECT_EQ(c(0, 1), 0);
}

namespace {

// Two hands swaying at 0.7 and 1.1 Hz, 5 cm and 0.3 rad, at 250 reports per second.
Pose swaying_hand(int controller, double t) {
  const double f = controller == 0 ? 0.7 : 1.1, side = controller == 0 ? -0.25 : 0.25;
  const double w = 2 * 3.141592653589793 * f;
  const Vec3 p(side + 0.05 * std::sin(w * t), 0.1 + 0.03 * std::cos(w * t), -0.3 + 0.02 * std::sin(2 * w * t));
  return pose_from(p, Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * std::sin(w * t), Vec3(0, 1, 0))));
}

struct GlitchRun {
  int published = 0, dropped = 0, degraded = 0, outside = 0;
};

// Reports of the swaying hands, with `glitch_every`-th report of controller 0 moved by
// `glitch_m` (0: none); each published pose is checked against the true one (the
// report's 1 mm quantisation is within the default covariance).
GlitchRun run_with_glitches(int glitch_every, double glitch_m) {
  HydraConfig c;
  c.device = "hydra";
  c.covariance = hydra_default_covariance();
  HydraStream stream(c);
  GlitchRun run;
  const std::int64_t period_us = 4000;
  for (int k = 0; k < 2500; ++k) {
    const double t = k * period_us * 1e-6;
    HydraReport report;
    for (int i = 0; i < 2; ++i) {
      const Pose truth = swaying_hand(i, t);
      report.controllers[i].position_m = truth.translation();
      report.controllers[i].orientation = Eigen::Quaterniond(truth.rotation());
    }
    if (glitch_every > 0 && k > 10 && k % glitch_every == 0) report.controllers[0].position_m.z() += glitch_m;
    auto parsed = parse_hydra_report(build_hydra_report(report));
    EXPECT_TRUE(parsed);
    const auto out = stream.on_report(*parsed, 1'000'000 + k * period_us);
    run.dropped += static_cast<int>(out.errors.size());
    for (const auto& s : out.samples) {
      ++run.published;
      run.degraded += s.status == TrackingStatus::Degraded;
      const Vec6 e = boxminus(swaying_hand(s.sensor == "left" ? 0 : 1, t), s.T_parent_child);
      run.outside += e.dot(s.covariance.ldlt().solve(e)) > 22.458;  // chi2(6) 99.9 %
    }
  }
  return run;
}

}  // namespace

TEST(HydraStream, CleanHandsLoseNothingToTheGate) {
  const GlitchRun run = run_with_glitches(0, 0);
  std::printf("clean: %d published, %d dropped, %d DEGRADED, %d outside their 99.9%% region\n", run.published,
              run.dropped, run.degraded, run.outside);
  EXPECT_EQ(run.dropped, 0);
  EXPECT_GE(run.published, 2 * 2500 - 2);  // only each stream's first report is held
  EXPECT_LE(run.degraded, run.published / 100);
  EXPECT_LE(run.outside, run.published / 1000);
}

TEST(HydraStream, MagneticJumpsAreDroppedOrCovered) {
  // 30 cm in one report: faster than any hand (75 m/s); dropped.
  GlitchRun run = run_with_glitches(50, 0.3);
  std::printf("30 cm jumps: %d published, %d dropped, %d DEGRADED, %d outside\n", run.published, run.dropped,
              run.degraded, run.outside);
  EXPECT_GE(run.dropped, 2500 / 50 - 2);
  EXPECT_LE(run.outside, run.published / 1000);
  // 2 cm in one report: possible for a hand (5 m/s) but 20 sigma from the prediction;
  // published DEGRADED with a covariance that covers it, or dropped.
  run = run_with_glitches(50, 0.02);
  std::printf("2 cm jumps: %d published, %d dropped, %d DEGRADED, %d outside\n", run.published, run.dropped,
              run.degraded, run.outside);
  EXPECT_GE(run.dropped + run.degraded, 2500 / 50 - 2);
  EXPECT_LE(run.outside, run.published / 1000);
}

TEST(HydraStream, LostRestartsTheGate) {
  HydraConfig c;
  c.device = "hydra";
  c.covariance = hydra_default_covariance();
  HydraStream stream(c);
  HydraReport report;
  report.controllers[0].position_m = Vec3(-0.2, 0, -0.3);
  report.controllers[1].position_m = Vec3(0.2, 0, -0.3);
  EXPECT_TRUE(stream.on_report(report, 1'000'000).samples.empty());  // held
  EXPECT_EQ(stream.on_report(report, 1'004'000).samples.size(), 2u);
  const auto lost = stream.lost(2'000'000);
  ASSERT_EQ(lost.size(), 2u);
  EXPECT_EQ(lost[0].status, TrackingStatus::Lost);
  test::expect_lost_covariance(lost[0].covariance);
  EXPECT_NEAR(lost[0].T_parent_child.translation().x(), -0.2, 1e-12);
  // Back 1 m away: a fresh start, not a jump.
  report.controllers[0].position_m = Vec3(-0.2, 1.0, -0.3);
  EXPECT_TRUE(stream.on_report(report, 3'000'000).samples.empty());
  const auto out = stream.on_report(report, 3'004'000);
  EXPECT_EQ(out.samples.size(), 2u);
  EXPECT_TRUE(out.errors.empty());
}
