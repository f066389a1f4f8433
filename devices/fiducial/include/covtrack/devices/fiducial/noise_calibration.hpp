#pragma once
// Measuring the corner noise model on rendered frames with known truth: the calibration
// procedure of the fiducial tracker (run by the honesty test fiducial_nees_test,
// which calibrates on one set of views and validates on another).
#include <cstdint>
#include <optional>
#include <vector>

#include "covtrack/devices/fiducial/corner_noise.hpp"
#include "covtrack/devices/fiducial/tag_detector.hpp"
#include "covtrack/devices/fiducial/tag_pose.hpp"
#include "covtrack/devices/fiducial/tag_renderer.hpp"

namespace covtrack::fiducial {

// One view: a tag, how it looks, how noisy the sensor is.
struct CalibrationView {
  RenderedTag tag;
  RenderLook look;
  double noise_sigma = 3;  // grey levels
  // Each draw moves the tag by up to this much (m, rad per axis), so that the
  // detector's sub-pixel bias varies between draws as it does for a moving camera.
  double jitter_m = 0.003, jitter_rad = 0.01;
};

// One draw of a view: the truth, and what the detector and the noise model saw.
struct ViewDraw {
  Pose T_camera_tag_true = Pose::Identity();
  std::optional<Detection> detection;
  CornerInputs inputs;                   // measured as the driver measures them
  std::array<cv::Point2d, 4> truth_px{};  // where the four corners truly project
};

// One draw's corner errors after the model's edge-shift correction (not its radial bias).
struct CornerErrors {
  std::array<cv::Point2d, 4> error_px{};  // corrected corner - truth
  double radial_px = 0;                   // the four corners' mean outward error
  std::array<double, 4> sq_px2{};         // per corner (u^2 + v^2), the common radial part removed
};
CornerErrors corner_errors(const CornerNoiseModel& model, const ViewDraw& draw);

// Renders, adds noise and detects `draws` times (on `threads` threads, each with its
// own detector); deterministic for a given seed.
Result<std::vector<ViewDraw>> draw_view(const CameraModel& camera, const DetectorOptions& detector,
                                        const CalibrationView& view, int draws,
                                        std::uint64_t seed, int threads = 2);

// The model's corner noise for what this draw's detection saw.
CornerNoise corner_noise(const CornerNoiseModel& model, const ViewDraw& draw);

// Four stages. (0) The edge shift: shift_px and shift_falloff by least squares of each
// edge's outward error (mean of its two corners along its normal) on white * reach.
// (1) The radial bias and spread: mean and standard deviation of the per-draw common
// radial error after that correction. (2) The four corner coefficients (floor, gain,
// aligned, shift_sigma) minimising the sum over views of log(view's corner NEES per
// coordinate)^2, so that over- and under-confident views weigh alike. (3) The four
// corners' errors are not independent (neighbours share an edge), so one common factor
// on the spreads brings the calibration views' pose NEES to 6, in geometric mean over views
// (the pooled mean would be set by the few most over-confident views).

CornerNoiseModel fit_corner_noise(const CameraModel& camera,
                                  const std::vector<CalibrationView>& views,
                                  const std::vector<std::vector<ViewDraw>>& draws);

// Mean pose NEES of the detected draws of one view under `model`; `count` gets how many.
double mean_pose_nees(const CameraModel& camera, const CalibrationView& view,
                      const std::vector<ViewDraw>& draws, const CornerNoiseModel& model,
                      int* count = nullptr);

}  // namespace covtrack::fiducial
