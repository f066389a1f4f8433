#pragma once
// A camera's image formation for rendered tags, with none of the one renderer's habits
// built in: the corner noise model is calibrated on some of these formations and judged
// on others, so what it learns is the detector's behaviour, not one edge profile.
//
// In order: the scene's radiance (linear, 1 = white paper at full exposure) by one of three
// independent rasterisers; lens distortion; the optics' point-spread function (a
// Gaussian and a defocus disk); vignetting; shot and read noise in linear light; the
// camera's tone curve (gamma); 8-bit quantisation; JPEG compression.
#include <cstdint>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "covtrack/emulators/fiducial/tag_renderer.hpp"
#include "covtrack/protocol/camera_opencv.hpp"
#include "tag_family.hpp"

namespace covtrack::fiducial {

enum class Rasteriser {
  // The tag's texture warped onto a grid `supersample` times finer, then area-averaged.
  Supersampled,
  // Each pixel's exact covered area of every cell, by clipping the projected cells
  // (straight-edged quads under a pinhole) to the pixel's light-sensitive square
  // (pixel_aperture).
  AnalyticArea,
  // Each pixel the mean of random points, one in each square of a 16 x 16 grid over the
  // pixel's light-sensitive part (pixel_aperture), each looked up in the tag's cells
  // through the inverse homography: no texture, no grid of samples shared by all pixels,
  // and a per-pixel pattern of small coverage errors fixed by jitter_seed.
  JitteredPoints,
};

struct ImageFormation {
  Rasteriser rasteriser = Rasteriser::AnalyticArea;
  int supersample = 4;           // Supersampled only
  double pixel_aperture = 1.0;   // AnalyticArea, JitteredPoints: the sensitive square's side / pitch
  std::uint64_t jitter_seed = 0; // JitteredPoints only
  double paper = 0.85, ink = 0.06, background = 0.4;  // linear reflectances
  double exposure = 1.0;         // linear signal of reflectance 1, in full scale
  double gauss_blur_px = 0.6;    // Gaussian PSF sigma (0: none)
  double defocus_radius_px = 0;  // disk PSF radius (0: none)
  double vignetting = 0;         // relative loss at the image's corner (cos^4-like, r^2)
  double full_well_e = 0;        // electrons at full scale for shot noise (0: none)
  double read_noise = 1.5;       // grey levels at full scale 255, in linear light
  double gamma = 1.0;            // the tone curve: grey = 255 * linear^(1 / gamma)
  int jpeg_quality = 0;          // 0: no compression
  int margin_cells = 1;          // white paper around each printed tag, in cells
  // Lens distortion applied when rendering (OpenCV order k1 k2 p1 p2 k3; empty: none).
  // The pose is then estimated with the camera model the caller holds, which may differ
  // (an imperfect calibration).
  cv::Mat true_distortion;
};

// The linear radiance of the tags over a flat background (CV_32F), sharp: pinhole, or
// through the lens of formation.true_distortion, each pixel the mean over its footprint.
cv::Mat tag_radiance(const Camera& camera, const TagFamily& family,
                     const std::vector<RenderedTag>& tags, const ImageFormation& formation);

// The 8-bit frame a camera with this formation delivers.
cv::Mat form_image(const Camera& camera, const TagFamily& family,
                   const std::vector<RenderedTag>& tags, const ImageFormation& formation,
                   std::mt19937_64& rng);

// The fraction of the unit pixel square centred on (x, y) that the convex polygon (up to 8
// vertices; NaN for more) covers.
double pixel_coverage(const std::vector<cv::Point2d>& convex_polygon, int x, int y);

}  // namespace covtrack::fiducial
