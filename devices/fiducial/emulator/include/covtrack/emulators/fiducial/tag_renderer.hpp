#pragma once
// Renders AprilTags at known poses through a pinhole camera: the emulated camera of the
// fiducial tracker, the input of its tests and of its calibration procedure.
// Anti-aliased by supersampling: each tag is warped onto a finer grid and area-averaged
// down, so edges land at sub-pixel positions the way a real lens and sensor put them.
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "covtrack/protocol/camera_opencv.hpp"
#include "covtrack/protocol/se3.hpp"
#include "tag_family.hpp"

namespace covtrack::fiducial {

// Tag frame (AprilTag 3's): origin at the tag centre, x right, y down as printed, z into
// the tag; `size_m` is the edge of the detected square (the black border's outer edge).
struct RenderedTag {
  int id = 0;
  double size_m = 0.1;
  Pose T_camera_tag = Pose::Identity();
};

struct RenderLook {
  double background = 128;   // grey level around the tags
  double black = 30, white = 220;  // the tag's two levels
  double blur_sigma_px = 0.8;  // Gaussian optical blur (0: none)
  int supersample = 4;         // sub-samples per pixel and axis
  int margin_cells = 1;        // white paper around the printed tag, in cells
};

// The noise-free image (CV_32F grey levels). Tags behind the camera are skipped.
// The camera's distortion is ignored: render through a distortion-free calibration.
cv::Mat render_tags(const Camera& camera, const TagFamily& family,
                    const std::vector<RenderedTag>& tags, const RenderLook& look);

// The 8-bit frame a sensor would deliver: clean + N(0, sigma^2) noise, rounded, clipped.
cv::Mat add_sensor_noise(const cv::Mat& clean, double noise_sigma, std::mt19937_64& rng);

// The homography from the tag plane's (x, y, 1) (metres) to image pixels (pixel centres at
// whole numbers) under the pinhole.
cv::Matx33d tag_plane_to_image(const Camera& camera, const Pose& T_camera_tag);

// Where the tag's four detected corners project, in the detector's order (AprilTag 3:
// tag-frame (-s/2, +s/2), (+s/2, +s/2), (+s/2, -s/2), (-s/2, -s/2)).
std::vector<cv::Point2d> projected_corners(const Camera& camera, const RenderedTag& tag);

}  // namespace covtrack::fiducial
