// The two edge biases the corner model corrects, each shown on renders with the truth:
// a camera's tone curve shrinks a dark square and grows a light one (the sign of
// scale_bias_per_blur, by polarity), and a lens's distortion bends the edges that
// AprilTag fits straight (lens_edge_bend.hpp).
#include <gtest/gtest.h>

#include <cstdio>

#include "covtrack/emulators/fiducial/noise_calibration.hpp"
#include "fiducial_scene.hpp"
#include "lens_edge_bend.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;

namespace {

// The mean over draws of the four edges' common outward error (px), with no correction.
double common_outward_error(const std::string& family, double gamma) {
  CalibrationView v;
  v.camera = test::camera(640, 480, 62);
  v.tag = {3, 0.15, test::tag_pose(0.8, 20, 5, 10)};
  v.formation.gamma = gamma;
  v.formation.gauss_blur_px = 0.8;
  DetectorOptions o;
  o.family = family;
  o.decimate = 1;
  auto draws = draw_view(o, v, 8, 1);
  EXPECT_TRUE(draws.has_value());
  CornerNoiseModel none;
  none.shift_px = 0, none.scale_bias_per_blur = 0;
  double sum = 0;
  int n = 0;
  for (const ViewDraw& d : *draws) {
    if (!d.detection) continue;
    for (double out : corner_errors(none, d).edge_out_px) sum += out / 4;
    ++n;
  }
  EXPECT_EQ(n, 8) << family;
  return n ? sum / n : 0;
}

}  // namespace

TEST(FiducialEdgeBias, ToneCurveShrinksADarkSquareAndGrowsALightOne) {
  const double dark_linear = common_outward_error("tag36h11", 1.0);
  const double light_linear = common_outward_error("tagStandard41h12", 1.0);
  const double dark_srgb = common_outward_error("tag36h11", 2.2);
  const double light_srgb = common_outward_error("tagStandard41h12", 2.2);
  std::printf("common outward error (px): gamma 1: dark %.3f, light %.3f; gamma 2.2: dark %.3f, light %.3f\n",
              dark_linear, light_linear, dark_srgb, light_srgb);
  EXPECT_LT(std::abs(dark_linear), 0.05);
  EXPECT_LT(std::abs(light_linear), 0.05);
  EXPECT_LT(dark_srgb, -0.15) << "a dark square must look smaller under a gamma-2.2 tone curve";
  EXPECT_GT(light_srgb, 0.15) << "a light square must look larger under a gamma-2.2 tone curve";
  // The model's default removes this bias with the polarity's sign.
  EXPECT_LT(CornerNoiseModel{}.scale_bias_per_blur, 0);
}

TEST(FiducialEdgeBias, LensBendCorrectionPutsCornersWhereTheLensDoes) {
  CalibrationView v;
  v.camera = test::camera(1920, 1080, 80);
  v.camera.k1 = -0.2, v.camera.k2 = 0.06;
  v.formation.true_distortion = distortion_vector(v.camera);
  v.formation.read_noise = 0.5;
  // A large tag towards the frame's corner, where the edges bend most.
  v.tag = {5, 0.2, test::tag_pose(0.8, 15, 5, 10, 0.35, 0.18)};
  DetectorOptions o;
  o.decimate = 2;
  auto draws = draw_view(o, v, 4, 2);
  ASSERT_TRUE(draws.has_value());
  double raw = 0, corrected = 0;
  int n = 0;
  for (const ViewDraw& d : *draws) {
    if (!d.detection) continue;
    const auto bend = straight_fit_corner_offsets(v.camera, d.detection->corners_px);
    for (std::size_t k = 0; k < 4; ++k) {
      raw += cv::norm(d.detection->corners_px[k] - d.truth_px[k]) / 4;
      corrected += cv::norm(d.detection->corners_px[k] - bend[k] - d.truth_px[k]) / 4;
    }
    ++n;
  }
  ASSERT_EQ(n, 4);
  raw /= n, corrected /= n;
  std::printf("mean corner error: %.3f px as detected, %.3f px after the bend correction\n", raw, corrected);
  EXPECT_GT(raw, 0.15) << "the scene must bend the edges enough to test the correction";
  EXPECT_LT(corrected, raw / 2);
}
