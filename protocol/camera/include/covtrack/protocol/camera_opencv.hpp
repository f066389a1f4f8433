#pragma once
// The camera model in OpenCV's forms (K, the distortion vector, the pinhole pixel), for
// code that calls OpenCV's calibration functions (the fiducial tracker, the OSG adapter's
// lens warp). Header only, so that the camera library itself needs no OpenCV headers in
// its interface; including this needs OpenCV's.
#include <opencv2/core.hpp>

#include "covtrack/protocol/camera.hpp"

namespace covtrack {

inline cv::Matx33d camera_matrix(const Camera& camera) {
  return {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
}

// k1 k2 p1 p2 k3, in OpenCV's order: a 5 x 1 CV_64F matrix.
inline cv::Mat distortion_vector(const Camera& camera) {
  return (cv::Mat_<double>(5, 1) << camera.k1, camera.k2, camera.p1, camera.p2, camera.k3);
}

// Pixel of a camera-frame point through the pinhole part only (no distortion), for code
// that undistorts its measured pixels first.
inline cv::Point2d pinhole_pixel(const Camera& camera, const Vec3& p_camera) {
  return {camera.fx * p_camera.x() / p_camera.z() + camera.cx, camera.fy * p_camera.y() / p_camera.z() + camera.cy};
}

}  // namespace covtrack
