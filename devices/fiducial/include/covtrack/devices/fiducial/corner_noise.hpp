#pragma once
// How well the detector places a tag corner, from what limits it (docs in
// devices/fiducial/README.md, "Corner noise model"):
//
//   sigma_corner^2 = floor_px^2 + gain_px^2 * (noise / contrast)^2 * 16 / max(16, L / 8)
//                    + aligned_px^2 * A
//
// noise: the image's noise (grey levels), contrast: the grey-level step across the tag's
// border, L: the tag's mean edge length (px). AprilTag fits each edge to max(16, L/8)
// sample points placed by the image gradient; each point's error grows with
// noise / contrast and the fitted line's end (the corner) averages them.
// A: how close the edges lie to the pixel axes (mean over edges of
// exp(-(angle to the nearest axis / 3 deg)^2)). AprilTag samples the edge gradient at
// whole pixels, so an edge along a pixel row sees the same sub-pixel phase all along and
// its bias does not average out (measured: 0.1 px at 0 deg against 0.05 px at 2-10 deg).
// On top of that, all four corners share one error along their radial directions (away
// from the quad's centre): the detector sees the square a little too small or too large,
// by radial_bias_px on average (corrected before the pose) with a spread of
// radial_sigma_px common to the four corners. Independent corner noise would average it
// away and make the depth over-confident, so it enters Sigma_c as a rank-one term.
// Each corner also gets narrow_px^2 (4 px / band)^power, band the quiet band beyond its
// narrower edge (quiet_band_px): where foreshortening squeezes the uniform margin beyond
// the black border to a few pixels, AprilTag's edge refinement reaches past it and the
// corner is biased (a constant of the view, up to 0.45 px on rendered tags).
// The floor holds what else noise does not explain (blur, aliasing, the lens).
// A calibration on rendered views with known truth measures the coefficients
// (fit_corner_noise in noise_calibration.hpp, run by tests/devices/fiducial_nees_test).
#include <array>

#include <opencv2/core.hpp>

namespace covtrack::fiducial {

struct CornerNoiseModel {
  double gain_px = 1.0;
  double floor_px = 0.05;
  double aligned_px = 0.1;
  double radial_bias_px = 0;   // mean outward error of every corner (negative: inward)
  double radial_sigma_px = 0;  // spread of that common radial error
  double narrow_px = 0;        // a corner's extra error where its quiet band is narrow
  double narrow_power = 6;     // how fast that error grows as the band narrows

  // The extra standard deviation (px) of a corner whose narrower edge has a quiet band
  // of `quiet_band_px`: narrow_px * (kNarrowBandPx / band)^(power / 2).
  double narrow_sigma_px(double quiet_band_px) const;
  // The same for the four corners (corner_quiet_band_px).
  std::array<double, 4> narrow_sigmas_px(const std::array<double, 4>& corner_band_px) const;
  static constexpr double kNarrowBandPx = 4;

  // One corner coordinate's standard deviation (px), the same along u and v.
  double sigma_px(double image_noise, double contrast, double edge_length_px,
                  double axis_alignment) const;
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

// A in the model above: 1 when every edge lies along a pixel row or column, ~0 beyond 6 deg.
double edge_axis_alignment(const std::array<cv::Point2d, 4>& corners_px);

double mean_edge_length_px(const std::array<cv::Point2d, 4>& corners_px);

// Width (px) of the quiet band beyond each edge of the detected square: `quiet_cells`
// cells (of cells_across_border per edge) measured outward from the edge's midpoint
// through the quad's perspective, as the distance to the edge's line. Edge e runs from
// corner e to corner e + 1.
std::array<double, 4> quiet_band_px(const std::array<cv::Point2d, 4>& corners_px,
                                    int cells_across_border, double quiet_cells);
// Per corner, the narrower band of its two edges (corner k joins edges k - 1 and k).
std::array<double, 4> corner_quiet_band_px(const std::array<cv::Point2d, 4>& corners_px,
                                           int cells_across_border, double quiet_cells);

}  // namespace covtrack::fiducial
