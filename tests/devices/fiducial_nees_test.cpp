// The fiducial tracker's covariance is honest on rendered images: the corner noise
// model is calibrated on one set of views and the pose NEES is checked on another
// (different poses, tag sizes, noise, contrast and blur), pooled and per view.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "covtrack/devices/fiducial/noise_calibration.hpp"
#include "covtrack/devices/fiducial/tag_pose.hpp"
#include "fiducial_scene.hpp"

using namespace covtrack;
using namespace covtrack::fiducial;

namespace {

constexpr int kCalibrationDraws = 100;
constexpr int kValidationDraws = 100;

DetectorOptions detector_options() {
  DetectorOptions o;
  o.decimate = 1;  // 320x240 frames: small tags need the full resolution to be found
  return o;
}

CalibrationView view(int id, double size_m, double distance_m, double yaw, double pitch,
                     double roll, double x_m, double y_m, double noise, double black,
                     double white, double blur) {
  CalibrationView v;
  v.tag = {id, size_m, test::tag_pose(distance_m, yaw, pitch, roll, x_m, y_m)};
  v.look.black = black, v.look.white = white, v.look.blur_sigma_px = blur;
  v.noise_sigma = noise;
  return v;
}

// Calibration views: their own sizes, distances, yaws and looks, none shared with
// validation but spanning its ranges (tag edge 25-70 px, black border 2-7 px, yaw 1-61 deg).
std::vector<CalibrationView> calibration_views() {
  std::vector<CalibrationView> v;
  const double sizes[] = {0.10, 0.12, 0.2, 0.25};
  const double noises[] = {1.5, 3, 5, 7, 10, 2.5};
  for (int i = 0; i < 18; ++i) {
    const double size = sizes[i % 4];
    const double yaw = std::fmod(4 + 17 * i, 62);
    // Steep views come nearer, so that every view is detected (none wasted).
    const double distance = size * (5 + 1.5 * (yaw > 40 ? i % 3 : i % 5));
    // Every third view has its edges along the pixel axes (roll 0 or 90 degrees).
    const double roll = i % 3 == 0 ? 90.0 * (i % 2) : 13.0 * i;
    v.push_back(view(i, size, distance, yaw, (i % 3 - 1) * 9.0, roll, 0.02 * (i % 3 - 1),
                     -0.015 * (i % 2), noises[i % 6], 25 + 7 * (i % 4), 200 + 5 * (i % 5),
                     0.6 + 0.1 * (i % 6)));
  }
  // Face-on, edges along the pixel axes, sharp: where the sub-pixel phase bias is largest
  // (the validation set has such views at yaw 0, so calibration needs its own).
  for (int i = 0; i < 6; ++i) {
    const double size = 0.11 + 0.03 * i;
    v.push_back(view(50 + i, size, size * (4.6 + 0.9 * (i % 3)), 1 + i % 3, i % 2 ? 2.0 : -2.0,
                     90.0 * (i % 2), 0.01 * (i % 3 - 1), 0.01, noises[(i + 2) % 6], 22 + 6 * i,
                     195 + 4 * i, 0.5 + 0.05 * (i % 3)));
  }
  return v;
}

// Validation views: 24, three tag sizes, 0.5-3 m, yaw 0-60 degrees.
std::vector<CalibrationView> validation_views() {
  struct Size { double size_m, near_m, far_m; };
  const Size sizes[] = {{0.08, 0.5, 0.9}, {0.16, 0.8, 1.7}, {0.30, 1.3, 3.0}};
  const double yaws[] = {0, 15, 30, 45, 60, 10, 35, 55};
  const double noises[] = {2, 4, 6, 8, 3, 5};
  std::vector<CalibrationView> v;
  int id = 20;
  for (const Size& s : sizes)
    for (int j = 0; j < 8; ++j, ++id) {
      // Steep views come nearer, so that the foreshortened tag stays detectable.
      const double f = (j % 4) / 3.0 * (yaws[j] > 40 ? 0.5 : 1.0);
      const double distance = s.near_m + f * (s.far_m - s.near_m);
      v.push_back(view(id, s.size_m, distance, yaws[j], (j % 3 - 1) * 7.0 + 3, 25.0 * j,
                       distance * 0.08 * ((j % 3) - 1), distance * 0.05 * ((j % 2) ? 1 : -1),
                       noises[id % 6], 20 + 10 * (j % 3), 190 + 10 * (j % 4), 0.5 + 0.15 * (j % 5)));
    }
  return v;
}

struct ViewNees {
  double mean_nees = 0;
  int detected = 0, ambiguous = 0;
  double sigma_px = 0, rms_corner_px = 0, edge_px = 0;
  double border_blur = 0;    // narrowest black border over the measured blur (mean over draws)
  double shift_px = 0;       // largest predicted shift of an edge's end (mean over draws)
  double bias_px = 0, spread_px = 0;  // rms over the 8 coordinates of the corrected corner error's mean / sd
};


ViewNees nees_of(const CameraModel& cam, const CalibrationView& v, const std::vector<ViewDraw>& draws,
                 const CornerNoiseModel& model) {
  ViewNees out;
  double sum = 0, sq = 0;
  Eigen::Matrix<double, 8, 1> e_sum = Eigen::Matrix<double, 8, 1>::Zero(), e_sq = e_sum;
  for (const ViewDraw& d : draws) {
    if (!d.detection) continue;
    const CornerErrors err = corner_errors(model, d);
    for (std::size_t k = 0; k < 4; ++k) {
      const cv::Point2d& e = err.error_px[k];  // after the edge-shift correction
      e_sum(2 * k) += e.x, e_sum(2 * k + 1) += e.y;
      e_sq(2 * k) += e.x * e.x, e_sq(2 * k + 1) += e.y * e.y;
      sq += err.sq_px2[k] / 8;
    }
    const auto& border = d.inputs.border_px;
    out.border_blur += *std::min_element(border.begin(), border.end()) / d.inputs.blur_px;
    double largest_shift = 0;
    for (const auto& ends : model.edge_shift_px(d.inputs))
      largest_shift = std::max({largest_shift, ends[0], ends[1]});
    out.shift_px += largest_shift;
    const CornerNoise noise = corner_noise(model, d);
    double variance = noise.sigma_px * noise.sigma_px;  // the corners' mean, edge-shift term included
    for (double extra : noise.extra_px) variance += extra * extra / 4;
    auto pose = estimate_tag_pose(cam, d.detection->corners_px, v.tag.size_m, noise);
    if (!pose) continue;
    const Vec6 e = boxminus(d.T_camera_tag_true, pose->best.T_camera_tag);
    sum += e.dot(pose->covariance.ldlt().solve(e));
    out.sigma_px += std::sqrt(variance);
    out.edge_px += d.inputs.edge_length_px;
    out.ambiguous += pose->ambiguous;
    ++out.detected;
  }
  if (out.detected) {
    out.mean_nees = sum / out.detected;
    out.sigma_px /= out.detected, out.edge_px /= out.detected;
    out.rms_corner_px = std::sqrt(sq / out.detected);
    out.border_blur /= out.detected, out.shift_px /= out.detected;
    const Eigen::Matrix<double, 8, 1> mean = e_sum / out.detected;
    const Eigen::Matrix<double, 8, 1> var = e_sq / out.detected - mean.cwiseProduct(mean);
    out.bias_px = std::sqrt(mean.squaredNorm() / 8);
    out.spread_px = std::sqrt(std::max(0.0, var.sum() / 8));
  }
  return out;
}

}  // namespace

TEST(FiducialNees, CalibratedCornerModelGivesHonestPoseCovariance) {
  const CameraModel cam = test::small_camera();
  std::vector<std::vector<ViewDraw>> calibration;
  std::uint64_t seed = 1;
  for (const auto& v : calibration_views()) {
    auto draws = draw_view(cam, detector_options(), v, kCalibrationDraws, seed++);
    ASSERT_TRUE(draws.has_value()) << draws.error().message;
    calibration.push_back(std::move(*draws));
  }
  for (std::size_t i = 0; i < calibration.size(); ++i) {
    const auto detected = std::count_if(calibration[i].begin(), calibration[i].end(),
                                        [](const ViewDraw& d) { return d.detection.has_value(); });
    EXPECT_GE(detected, kCalibrationDraws * 9 / 10) << "calibration view " << i << " is wasted";
  }
  const CornerNoiseModel model = fit_corner_noise(cam, calibration_views(), calibration);
  std::printf("calibrated corner model: gain %.3f px, floor %.4f px, axis-aligned %.4f px, "
              "edge shift %.4f px (falloff %.2f, sigma %.4f px), radial bias %.4f px, radial sigma "
              "%.4f px\n",
              model.gain_px, model.floor_px, model.aligned_px, model.shift_px, model.shift_falloff,
              model.shift_sigma_px, model.radial_bias_px, model.radial_sigma_px);
  std::printf("calibration views' NEES:");
  for (std::size_t i = 0; i < calibration.size(); ++i)
    std::printf(" %.1f", mean_pose_nees(cam, calibration_views()[i], calibration[i], model));
  std::printf("\n");

  double pooled_sum = 0;
  int pooled_n = 0, within_2x = 0;
  std::printf("%4s %5s %5s %5s %5s %6s %5s %5s %6s %7s %6s %6s %7s %5s %4s\n", "view", "size", "dist",
              "yaw", "noise", "edge", "bo/bl", "shift", "sigma", "rmsCorn", "bias", "spread", "NEES", "det", "amb");
  const auto views = validation_views();
  for (std::size_t i = 0; i < views.size(); ++i) {
    const auto& v = views[i];
    auto draws = draw_view(cam, detector_options(), v, kValidationDraws, 1000 + i);
    ASSERT_TRUE(draws.has_value()) << draws.error().message;
    const ViewNees n = nees_of(cam, v, *draws, model);
    const double yaw = std::atan2(-v.tag.T_camera_tag.rotation()(2, 0), v.tag.T_camera_tag.rotation()(2, 2));
    std::printf("%4zu %5.2f %5.2f %5.0f %5.1f %6.1f %5.2f %5.3f %6.3f %7.3f %6.3f %6.3f %7.2f %5d %4d\n", i,
                v.tag.size_m, v.tag.T_camera_tag.translation().z(), yaw * 180 / M_PI, v.noise_sigma,
                n.edge_px, n.border_blur, n.shift_px, n.sigma_px, n.rms_corner_px, n.bias_px, n.spread_px,
                n.mean_nees, n.detected, n.ambiguous);
    EXPECT_GE(n.detected, kValidationDraws * 9 / 10) << "view " << i;
    // The bar: no view more than 2x over- or under-confident (NEES in [3, 12]).
    EXPECT_LE(n.mean_nees, 12.0) << "view " << i << " is over 2x over-confident";
    EXPECT_GE(n.mean_nees, 3.0) << "view " << i << " is over 2x under-confident";
    within_2x += n.mean_nees >= 3.0 && n.mean_nees <= 12.0;
    pooled_sum += n.mean_nees * n.detected;
    pooled_n += n.detected;
  }
  // chi-square(6): mean 6, variance 12; 99% two-sided bounds of a mean of n draws.
  const double pooled = pooled_sum / pooled_n;
  const double half_width = 2.576 * std::sqrt(12.0 / pooled_n);
  std::printf("pooled mean NEES %.3f over %d draws; chi2(6) 99%% bounds [%.3f, %.3f]\n", pooled,
              pooled_n, 6 - half_width, 6 + half_width);
  std::printf("views within 2x (mean NEES in [3, 12]): %d of %zu\n", within_2x, views.size());
  // The bar for the pooled set.
  EXPECT_GT(pooled, 6 - half_width);
  EXPECT_LT(pooled, 6 + half_width);
}
