#include "covtrack/devices/fiducial/camera_model.hpp"

#include <fmt/format.h>

#include "covtrack/client/camera.hpp"

namespace covtrack::fiducial {

// The client's reader is the one reader of calibration files; this only changes the form.
Result<CameraModel> load_camera_model(const std::filesystem::path& path) {
  const auto camera = client::load_camera(path);
  if (!camera) return std::unexpected(camera.error());
  CameraModel cam;
  cam.width_px = camera->width_px, cam.height_px = camera->height_px;
  cam.fx = camera->fx, cam.fy = camera->fy, cam.cx = camera->cx, cam.cy = camera->cy;
  cam.distortion = (cv::Mat_<double>(5, 1) << camera->k1, camera->k2, camera->p1, camera->p2, camera->k3);
  return cam;
}

Result<void> save_camera_model(const CameraModel& camera, const std::filesystem::path& path) {
  try {
    cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
    if (!fs.isOpened()) return fail(fmt::format("{}: cannot write", path.string()));
    fs << "image_width" << camera.width_px << "image_height" << camera.height_px;
    fs << "camera_matrix" << cv::Mat(camera.K());
    fs << "distortion_coefficients" << camera.distortion;
  } catch (const cv::Exception& e) {
    return fail(fmt::format("{}: cannot write: {}", path.string(), e.what()));
  }
  return {};
}

}  // namespace covtrack::fiducial
