#pragma once
// A lens with distortion bends a tag's straight edges, and AprilTag fits straight lines
// to them: each reported corner is where two fitted lines cross, not where the lens puts
// the corner. On a 1920x1080 camera with k1 = -0.12 a 300 px tag's corners are off by
// 0.1-0.4 px that way (measured by fiducial_heldout_nees_test), many times the noise of
// so large a tag. The offset follows from the calibration alone, so it is removed.
#include <array>

#include <opencv2/core.hpp>

#include "covtrack/protocol/camera_opencv.hpp"

namespace covtrack::fiducial {

// For a quad whose corners are `corners_px` in the distorted image: how far the crossings
// of straight lines fitted along each bent edge lie from the corners (px, per corner,
// AprilTag's order). Zero without distortion.
std::array<cv::Point2d, 4> straight_fit_corner_offsets(const Camera& camera,
                                                       const std::array<cv::Point2d, 4>& corners_px);

}  // namespace covtrack::fiducial
