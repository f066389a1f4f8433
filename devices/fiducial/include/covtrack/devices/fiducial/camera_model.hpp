#pragma once
// The camera intrinsics the fiducial tracker needs, in OpenCV's form (K, distortion
// vector), read by the client's calibration reader (client/camera.hpp).
// Camera frame as in OpenCV: +z forward, x right, y down; pixel centres at integers.
#include <filesystem>

#include <opencv2/core.hpp>

#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::fiducial {

struct CameraModel {
  int width_px = 0, height_px = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;  // px
  cv::Mat distortion = cv::Mat::zeros(5, 1, CV_64F);  // k1 k2 p1 p2 k3 (OpenCV order)

  cv::Matx33d K() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
  bool has_distortion() const { return cv::countNonZero(distortion) > 0; }
  // Pixel of a camera-frame point through the pinhole part only (no distortion).
  cv::Point2d project(const Vec3& p_camera) const {
    return {fx * p_camera.x() / p_camera.z() + cx, fy * p_camera.y() / p_camera.z() + cy};
  }
};

// Errors name the file and the key.
Result<CameraModel> load_camera_model(const std::filesystem::path& file);

// Writes `camera` in the same layout (used by the renderer for its emulated camera).
Result<void> save_camera_model(const CameraModel& camera, const std::filesystem::path& file);

}  // namespace covtrack::fiducial
