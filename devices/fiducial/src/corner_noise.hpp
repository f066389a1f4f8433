#pragma once
// How well the detector places a tag corner, from what limits it (docs in
// devices/fiducial/README.md, "Corner noise model"):
//
//   per corner coordinate:  sigma^2 = floor_px^2 + aligned_px^2 * A
//                                     + shift_sigma_px^2 * (reach_a^2 + reach_b^2)
//   per edge end:           line^2  = (sample_floor_px^2 + gain_px^2 * (noise / contrast)^2)
//                                     * 16 / max(16, L / 8)
//
// noise: the image noise at the tag's edges (grey levels: measure_corner_inputs),
// contrast: the grey-level step across the tag's border, L: the tag's mean edge length
// (px). AprilTag fits each edge to max(16, L/8) sample points placed by the image
// gradient; each point's error grows with
// noise / contrast and the fitted line's end (the corner) averages them. Each point also
// has an error that image noise does not explain and that differs from point to point
// (where the edge crosses the pixel grid, the interpolation): the line averages it the
// same way (sample_floor_px), so for tags with edges over 128 px it shrinks as 128 / L.
// A least-squares line's ends are correlated -1/2: of line^2, a quarter moves the edge's
// line out (both ends alike) and three quarters turn it (the ends opposite), measured on
// the draw-to-draw corner errors of both rasterisers. What stays for any size and is
// independent per coordinate is floor_px.
// A: how close the edges lie to the pixel axes (mean over edges of
// exp(-(angle to the nearest axis / 3 deg)^2)). AprilTag samples the edge gradient at
// whole pixels, so an edge along a pixel row sees the same sub-pixel phase all along and
// its bias does not average out (measured: 0.1 px at 0 deg against 0.05 px at 2-10 deg).
//
// Phase-locked edges: that bias is shared by the whole edge, so it places and turns the
// edge's line as a systematic error of the view, not as corner noise. What decides it is
// how far the edge drifts across the pixel grid from one end to the other, D = L_e
// |sin(angle to the nearest axis)| (px), not the angle: a 45 px edge at 0.3 deg drifts
// 0.24 px and is locked, a 150 px one at the same angle is not. Per edge, lock =
// exp(-(D / 0.5 px)^2); its line's outward error gains locked_edge_px^2 * lock (measured on
// rendered views: 0.1 px outward for edges under 0.25 px of drift, 0.02 px beyond 1 px).
// The turn stays locked longer: an edge that sweeps about one pixel phase cycle along its
// length gets an interpolation error that rises along it, which a line fit takes as a
// turn, and averages only beyond ~2 cycles; its turn gains locked_tilt_px^2 *
// exp(-(D / 1.5 px)^2) (turn_lock).
//
// Edge shift: the black border is one cell thick; where a white data cell lines its
// inside, the blurred image rises again within a few pixels of the edge, and AprilTag's
// edge refinement (gradients sampled up to 3 px either side) finds the edge too far out.
// Per edge, reach = exp(-shift_falloff (border / blur)^2), border the black border's
// width along the edge's normal (px) and blur the measured edge blur (px); the edge is
// moved back in by shift_px * white * reach before the pose (white: where white cells
// line that edge, from the tag's code, as a straight line along it: the shift is
// evaluated at each end, so cells near one corner tilt the line). It is a bias of the
// view (up to 0.45 px at a corner of a rendered small steep tag), constant across noise
// draws: it is corrected, and what the correction misses enters each corner's variance
// as shift_sigma_px^2 times the squared reaches of its two edges (a, b).
//
// On top of that, the corners share systematic errors that independent corner noise would
// average away: where a camera's tone curve, point-spread function, sharpening or
// compression put the edge of a blurred dark-to-light step is not where the step is, by an
// amount that grows with the blur and whose sign depends on the tag's polarity. Each
// edge's line is placed off by its own error (edge_sigma, shared by the edge's two
// corners), turned by its own error (tilt_sigma: its two ends off in opposite senses)
// and all four edges by a common one (scale_sigma: the square looks too large or
// too small, which moves the pose along the line of sight). Each grows with the measured
// blur: sigma = hypot(floor, per_blur * blur); an edge's own placement and turn also fall
// with its length, as 64 px / L (size_factor: measured on rendered views, the turns of
// edges under 50 px were 4.5x a constant spread's, of 80-120 px 2.5x, and the constant
// spread was their average). Their mean is not zero: a tone curve that
// lifts the mid-tones (gamma above 1, as in sRGB) grows the light side into the dark one
// (0.35-0.45 px per px of blur at gamma 2.2), so a dark square looks smaller and a light one (reversed-border
// families) larger. scale_bias_per_blur * blur, signed by the polarity, is moved out of
// every edge before the pose; the spread about it is scale_sigma. A camera's own
// calibration narrows both. The floor holds what else noise does not explain.
// A calibration on rendered views with known truth measures the coefficients
// (fit_corner_noise in noise_calibration.hpp, run by tests/devices/fiducial_heldout_nees_test).
#include <array>
#include <cstddef>
#include <limits>

#include <opencv2/core.hpp>

#include "tag_detector.hpp"
#include "tag_pose.hpp"

namespace covtrack::fiducial {

// What the model reads from one detection in one frame: all of it measured from the
// image and the detection, by the driver and by the calibration alike.
struct CornerInputs {
  double image_noise = 0;     // grey levels, at the tag's edges (measure_corner_inputs)
  double contrast = 0;        // grey levels (tag_contrast)
  double edge_length_px = 0;  // mean edge length
  double axis_alignment = 0;  // A (edge_axis_alignment)
  std::array<double, 4> phase_lock{};  // per edge (edge_phase_lock)
  std::array<double, 4> turn_lock{};   // per edge, the turn's (edge_phase_lock, 1.5 px wide)
  double blur_px = 1;         // edge_blur_px
  std::array<double, 4> border_px{};   // per edge: the black border's width (border_width_px)
  std::array<std::array<double, 2>, 4> inner_white{};  // per edge, at its start and end:
                                                       // TagFamily::border_inner_white
  double polarity = 1;        // +1 dark square on light, -1 light on dark (reversed border)
};

// The defaults are what fiducial_heldout_nees_test calibrates on its rendered camera
// population (tone curves gamma 1-2.4, blur 0.4-1.25 px plus defocus, JPEG 75-97 or none;
// devices/fiducial/README.md); config/schema.md lists the same values.
struct CornerNoiseModel {
  double gain_px = 1.2299;
  double floor_px = 0.0001;         // independent of the tag's size
  double sample_floor_px = 0.0368;  // per edge sample: averaged by the edge fit (above)
  double aligned_px = 0.0141;
  double shift_px = 2.1957;        // outward edge shift with all-white cells inside, zero border
  double shift_falloff = 0.21;     // how fast it fades with border / blur (see above)
  double shift_sigma_px = 1.8642;  // the shift correction's uncertainty at reach 1
  double scale_bias_per_blur = -0.2574;  // every edge's mean outward error per px of blur,
                                         // for a dark square (a light one: the opposite)
  double scale_sigma_px = 0.0258;     // the four edges' common outward error: its floor
  double scale_per_blur = 0.1331;  //   and its growth per px of edge blur
  double edge_sigma_px = 0.0108;   // each edge's own outward error at 64 px: its floor
  double edge_per_blur = 0.0;      //   and its growth per px of edge blur
  double tilt_sigma_px = 0.0124;   // each edge's own turn at 64 px (its ends' opposite outward
  double tilt_per_blur = 0.0;      //   errors, px at each end): floor and growth per px blur
  // A phase-locked edge's own outward error and turn (px), at lock 1: fitted apart from the
  // rest (fit_locked_edges in noise_calibration.hpp), on views made to have such edges.
  double locked_edge_px = 0.0661;
  double locked_tilt_px = 0.0807;

  // Per edge: exp(-shift_falloff (border / blur)^2).
  std::array<double, 4> edge_reach(const CornerInputs& in) const;
  // Per edge, at its start and end corner: the predicted outward shift (px),
  // shift_px * white * reach + polarity * scale_bias_per_blur * blur.
  EdgeShifts edge_shift_px(const CornerInputs& in) const;
  // One corner coordinate's independent standard deviation (px): the floor and the
  // pixel-axis term (not the edge shift's, not the line fit's).
  double sigma_px(const CornerInputs& in) const;
  // Per edge end, the line fit's standard deviation (px): the samples' errors (image noise
  // and the per-sample floor) averaged by the fit.
  double line_sigma(const CornerInputs& in) const;
  // The systematic edge errors' standard deviations (px) for this detection's blur.
  double scale_sigma(const CornerInputs& in) const;
  double edge_sigma(const CornerInputs& in) const;
  double tilt_sigma(const CornerInputs& in) const;
  // Everything estimate_tag_pose needs.
  CornerNoise noise(const CornerInputs& in) const;
  // How the edge fit averages its samples' errors: 16 / max(16, L / 8).
  static double sample_factor(double edge_length_px);
  // How an edge's own placement and turn spreads scale with its length: 64 / max(16, L),
  // so edge_sigma_px and tilt_sigma_px (and their growth per blur) are those at 64 px.
  static double size_factor(double edge_length_px);
  // The noise-driven factor the gain multiplies: (noise / contrast)^2 * sample_factor(L).
  static double noise_term(double image_noise, double contrast, double edge_length_px);
};

// All inputs for one detection; `image_noise` is the frame's (computed once per frame).
// The detection's noise input is the root mean square of the noise in the rings inside
// and outside its edges (ring_noise), each ring's variance drawn towards the frame's as
// if the frame's were 32 responses more (a small tag's ring gives a few dozen, whose
// median scatters by 15-20%: a ring read low by chance would make the pose over-confident).
// The frame's stands in for a ring too thin to read.
CornerInputs measure_corner_inputs(const cv::Mat& gray, const Detection& detection,
                                   const TagFamily& family, double image_noise);

// The image's noise standard deviation (grey levels), from the median absolute response
// of a 3x3 second-difference filter on a sparse grid of 2x2-pixel block sums (robust to
// the few edge pixels, and to JPEG, which removes the finest-scale noise).
double estimate_image_noise(const cv::Mat& gray);

// The noise in the one-cell ring along the detected square's edges (grey levels), inside
// it (`outside` false: the tag's border) or outside it (the ring every family keeps in
// the other colour), by the same 2x2-block measure as estimate_image_noise, along the
// ring's middle at 4 px steps (so that successive blocks never share a pixel at any edge
// angle). A tone curve makes noise depend on the grey level (gamma 2.2 on linear sensor
// noise: ~3x as large at the ink's level as at the paper's), so the frame's noise, read
// where most of the frame is, is not the noise at either side of a tag's edge. sigma is
// NaN where the ring is under 4 px wide or gives under 16 responses.
struct RingNoise {
  double sigma = std::numeric_limits<double>::quiet_NaN();  // grey levels
  std::size_t responses = 0;                                // how many it rests on
};
RingNoise ring_noise(const cv::Mat& gray, const std::array<cv::Point2d, 4>& corners_px,
                     const std::array<double, 4>& border_px, bool outside);

// Grey-level step across the detected square's edges: samples half a cell inside and
// half a cell outside each edge, at a quarter, half and three quarters of its length.
double tag_contrast(const cv::Mat& gray, const std::array<cv::Point2d, 4>& corners_px,
                    int cells_across_border);

// How wide the tag's edges are (px): the Gaussian blur sigma that gives the measured
// peak slope across the border edges for the measured `contrast` (tag_contrast). It
// includes the lens blur, the pixel's area and the interpolation.
double edge_blur_px(const cv::Mat& gray, const std::array<cv::Point2d, 4>& corners_px,
                    double contrast);

// A in the model above: 1 when every edge lies along a pixel row or column, ~0 beyond 6 deg.
double edge_axis_alignment(const std::array<cv::Point2d, 4>& corners_px);

// Per edge, how much its sub-pixel phase stays the same along it: exp(-(D / width)^2),
// D its drift across the pixel grid (see the model above; the turn's lock is wider).
std::array<double, 4> edge_phase_lock(const std::array<cv::Point2d, 4>& corners_px, double width_px = 0.5);

double mean_edge_length_px(const std::array<cv::Point2d, 4>& corners_px);

// Width (px) of the one-cell black border inside each edge of the detected square (of
// cells_across_border cells per edge), along the edge's normal at its midpoint, through
// the quad's perspective. Edge e runs from corner e to corner e + 1.
std::array<double, 4> border_width_px(const std::array<cv::Point2d, 4>& corners_px,
                                      int cells_across_border);

}  // namespace covtrack::fiducial
