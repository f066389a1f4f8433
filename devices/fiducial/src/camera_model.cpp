#include "covtrack/devices/fiducial/camera_model.hpp"

#include <fmt/format.h>

namespace covtrack::fiducial {
namespace {

Result<cv::Mat> read_matrix(const cv::FileStorage& fs, const std::string& file, const char* key) {
  const cv::FileNode node = fs[key];
  if (node.empty()) return fail(fmt::format("{}: missing key '{}'", file, key));
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception& e) {
    return fail(fmt::format("{}: key '{}' is not a matrix: {}", file, key, e.what()));
  }
  if (m.empty()) return fail(fmt::format("{}: key '{}' is not a matrix", file, key));
  m.convertTo(m, CV_64F);
  return m.reshape(1, static_cast<int>(m.total()));
}

Result<int> read_positive_int(const cv::FileStorage& fs, const std::string& file, const char* key) {
  const cv::FileNode node = fs[key];
  if (node.empty()) return fail(fmt::format("{}: missing key '{}'", file, key));
  if (!node.isInt()) return fail(fmt::format("{}: key '{}' is not an integer", file, key));
  const int v = static_cast<int>(node);
  if (v <= 0) return fail(fmt::format("{}: key '{}' must be positive, is {}", file, key, v));
  return v;
}

}  // namespace

Result<CameraModel> load_camera_model(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return fail(fmt::format("{}: calibration file not found", file));
  cv::FileStorage fs;
  try {
    if (!fs.open(file, cv::FileStorage::READ))
      return fail(fmt::format("{}: cannot open as an OpenCV calibration file", file));
  } catch (const cv::Exception& e) {
    return fail(fmt::format("{}: not a readable OpenCV calibration file: {}", file, e.what()));
  }
  CameraModel cam;
  auto w = read_positive_int(fs, file, "image_width");
  if (!w) return std::unexpected(w.error());
  auto h = read_positive_int(fs, file, "image_height");
  if (!h) return std::unexpected(h.error());
  cam.width_px = *w, cam.height_px = *h;

  auto K = read_matrix(fs, file, "camera_matrix");
  if (!K) return std::unexpected(K.error());
  if (K->total() != 9) return fail(fmt::format("{}: key 'camera_matrix' must be 3x3", file));
  const auto k = [&](int i) { return K->at<double>(i); };
  cam.fx = k(0), cam.cx = k(2), cam.fy = k(4), cam.cy = k(5);
  if (!(cam.fx > 0 && cam.fy > 0) || k(1) != 0 || k(3) != 0 || k(6) != 0 || k(7) != 0 ||
      k(8) != 1 || !std::isfinite(cam.cx) || !std::isfinite(cam.cy))
    return fail(fmt::format(
        "{}: key 'camera_matrix' is not a pinhole matrix [fx 0 cx; 0 fy cy; 0 0 1]", file));

  auto dist = read_matrix(fs, file, "distortion_coefficients");
  if (!dist) return std::unexpected(dist.error());
  const int n = static_cast<int>(dist->total());
  if (n < 4)
    return fail(fmt::format("{}: key 'distortion_coefficients' needs 4 or 5 values, has {}", file, n));
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(dist->at<double>(i)) || (i >= 5 && dist->at<double>(i) != 0))
      return fail(fmt::format("{}: key 'distortion_coefficients': coefficient {} is not finite or "
                              "beyond k1 k2 p1 p2 k3",
                              file, i));
  cam.distortion = cv::Mat::zeros(5, 1, CV_64F);
  for (int i = 0; i < std::min(n, 5); ++i) cam.distortion.at<double>(i) = dist->at<double>(i);
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
