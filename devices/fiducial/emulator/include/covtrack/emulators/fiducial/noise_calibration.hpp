#pragma once
// Measuring the corner noise model on rendered frames with known truth: the calibration
// procedure of the fiducial tracker (run by the honesty test fiducial_heldout_nees_test,
// which calibrates on one set of views and validates on another).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "corner_noise.hpp"
#include "covtrack/emulators/fiducial/tag_image_formation.hpp"
#include "tag_detector.hpp"
#include "tag_pose.hpp"

namespace covtrack::fiducial {

// One view: a tag, the camera model the driver is given (its pinhole part also renders)
// and the camera's image formation (which may have a lens unlike the model's).
struct CalibrationView {
  Camera camera;
  RenderedTag tag;
  ImageFormation formation;
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
  // How far AprilTag's straight fit of the lens's bent edges puts each corner, by the
  // camera model the driver is given (straight_fit_corner_offsets): the driver removes it
  // before the pose, so the calibration's errors leave it out as well.
  std::array<cv::Point2d, 4> lens_bend_px{};
};

// One draw's corner errors after the model's edge-shift correction and the lens bend's.
struct CornerErrors {
  std::array<cv::Point2d, 4> error_px{};  // corrected corner - truth
  std::array<double, 4> edge_out_px{};    // per edge: its two corners' mean error along its normal
  std::array<double, 4> edge_turn_px{};   // per edge: half its start's minus its end's error
};
CornerErrors corner_errors(const CornerNoiseModel& model, const ViewDraw& draw);

// Renders (form_image), detects `draws` times (on `threads` threads, each with its
// own detector, kept for the calling thread's next views of the same family);
// deterministic for a given seed.
Result<std::vector<ViewDraw>> draw_view(const DetectorOptions& detector,
                                        const CalibrationView& view, int draws,
                                        std::uint64_t seed, int threads = 2);

// The model's corner noise for what this draw's detection saw.
CornerNoise corner_noise(const CornerNoiseModel& model, const ViewDraw& draw);

// Four stages (devices/fiducial/README.md, "Calibration procedure").
// (1) The predicted edge shifts: shift_px, shift_falloff and scale_bias_per_blur by least
//     squares of each edge's outward error on white * reach and on polarity * blur.
// (2) The independent corner coefficients (floor, sample floor, gain, aligned,
//     shift_sigma) on the draw-to-draw spread of each corner about its view's mean,
//     minimising the sum over views of log(view's corner NEES per coordinate)^2, so that
//     over- and under-confident views weigh alike.
// (3) The systematic terms from the views' mean edge errors: their common part (scale)
//     and the rest (edge), and the ends' opposite parts (tilt), each as floor^2 + (per_blur * blur)^2 by least squares over
//     views, less the means' own sampling variance.
// (4) One common factor on every spread so that the pooled pose NEES of the calibration
//     draws is 6.
CornerNoiseModel fit_corner_noise(const std::vector<CalibrationView>& views,
                                  const std::vector<std::vector<ViewDraw>>& draws);

// The phase-locked edges' terms (locked_edge_px, locked_tilt_px; corner_noise.hpp) by
// least squares of each detected edge's squared outward error and turn, less the rest of
// `model`'s variance for them, on its lock: on views made to have such edges (few views of
// a random set do). The other coefficients are kept.
void fit_locked_edges(CornerNoiseModel& model, const std::vector<std::vector<ViewDraw>>& draws);

// The coefficients on one line, as the calibration reports them.
std::string describe(const CornerNoiseModel& model);

// Mean pose NEES of the detected draws of one view under `model`; `count` gets how many.
double mean_pose_nees(const CalibrationView& view,
                      const std::vector<ViewDraw>& draws, const CornerNoiseModel& model,
                      int* count = nullptr);

}  // namespace covtrack::fiducial
