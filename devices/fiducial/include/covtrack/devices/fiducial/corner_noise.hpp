#pragma once
// How well the detector places a tag corner, from what limits it (docs in
// devices/fiducial/README.md, "Corner noise model"):
//
//   sigma_corner^2 = floor_px^2 + gain_px^2 * (noise / contrast)^2 * 16 / max(16, L / 8)
//
// noise: the image's noise (grey levels), contrast: the grey-level step across the tag's
// border, L: the tag's mean edge length (px). AprilTag fits each edge to max(16, L/8)
// sample points placed by the image gradient; each point's error grows with
// noise / contrast and the fitted line's end (the corner) averages them. The floor holds
// what noise does not explain (blur, aliasing, the lens); a calibration measures it per
// camera (covtrack calibrate-fiducial).
#include <array>

#include <opencv2/core.hpp>

namespace covtrack::fiducial {

struct CornerNoiseModel {
  double gain_px = 1.0;
  double floor_px = 0.05;

  // One corner coordinate's standard deviation (px), the same along u and v.
  double sigma_px(double image_noise, double contrast, double edge_length_px) const;
  // The noise-driven factor the gain multiplies: (noise / contrast)^2 * 16 / max(16, L/8).
  static double noise_term(double image_noise, double contrast, double edge_length_px);
};

// The image's noise standard deviation (grey levels), from the median absolute response
// of a 3x3 second-difference filter on a sparse grid (robust to the few edge pixels).
double estimate_image_noise(const cv::Mat& gray);

// Grey-level step across the detected square's edges: samples half a cell inside and
// half a cell outside each edge, at a quarter, half and three quarters of its length.
double tag_contrast(const cv::Mat& gray, const std::array<cv::Point2d, 4>& corners_px,
                    int cells_across_border);

double mean_edge_length_px(const std::array<cv::Point2d, 4>& corners_px);

}  // namespace covtrack::fiducial
