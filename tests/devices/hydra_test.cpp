// Razer Hydra: the report parser on reports built from the documented format, the
// hemisphere resolution, the mode-switch feature reports, and a clear error without one.
#include <gtest/gtest.h>

#include <chrono>

#include "capture_sink.hpp"
#include "covtrack/devices/hydra/hydra_driver.hpp"
#include "covtrack/devices/hydra/hydra_report.hpp"

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
