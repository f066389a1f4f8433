#include "covtrack/protocol/camera.hpp"
#include "covtrack/protocol/camera_opencv.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "calibration_text.hpp"
#include "isolated_read.hpp"

#include <string>

namespace covtrack {

Vec2 Camera::project(const Vec3& p, Mat23* J_pixel_point) const {
  const double iz = 1.0 / p.z();
  const double x = p.x() * iz, y = p.y() * iz;
  Vec2 pixel;
  if (!J_pixel_point) {
    pixel_of_normalised(x, y, pixel.x(), pixel.y());
    return pixel;
  }
  // Chain rule: pixel <- normalised (x, y) <- point.
  double d[4];
  pixel_of_normalised(x, y, pixel.x(), pixel.y(), d);
  Mat2 D;
  D << d[0], d[1], d[2], d[3];
  Mat23 N;
  N << iz, 0, -x * iz, 0, iz, -y * iz;
  *J_pixel_point = D * N;
  return pixel;
}

double Camera::distortion_fold_r2() const {
  // Every projection of a frame asks with the same coefficients; the search below costs
  // about a microsecond, which per object was most of the projection's time.
  thread_local struct {
    double k1 = 0, k2 = 0, k3 = 0, fold_r2 = std::numeric_limits<double>::infinity();
  } last;
  if (last.k1 == k1 && last.k2 == k2 && last.k3 == k3) return last.fold_r2;
  // d(r radial)/dr = 1 + 3 k1 x + 5 k2 x^2 + 7 k3 x^3 with x = r^2: positive at 0; the
  // first sign change, searched on a geometric grid up to x = 1e4 (89.4 degrees off-axis)
  // and refined by bisection.
  const auto slope = [&](double x) { return 1 + x * (3 * k1 + x * (5 * k2 + x * 7 * k3)); };
  double fold_r2 = std::numeric_limits<double>::infinity(), lo = 0;
  for (double hi = 1e-4; hi <= 1e4; lo = hi, hi *= 1.1) {
    if (slope(hi) > 0) continue;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (slope(mid) > 0 ? lo : hi) = mid;
    }
    fold_r2 = lo;
    break;
  }
  last = {k1, k2, k3, fold_r2};
  return fold_r2;
}

Mat2 Camera::intrinsic_covariance_at(const Vec2& pixel) const {
  if (intrinsic_sigmas_px.isZero()) return Mat2::Zero();
  // u = fx xd + cx, v = fy yd + cy: d(u,v)/d(fx,fy,cx,cy) = [xd 0 1 0; 0 yd 0 1].
  const Vec2 centred = pixel - Vec2(cx, cy);
  Eigen::Matrix<double, 2, 4> J;
  J << centred.x() / fx, 0, 1, 0, 0, centred.y() / fy, 0, 1;
  const Eigen::Vector4d var = intrinsic_sigmas_px.cwiseAbs2();
  return J * var.asDiagonal() * J.transpose();
}

namespace {

// A ROS camera_info matrix: {rows, cols, data: [...]} without OpenCV's type tag.
Result<cv::Mat> read_untagged_matrix(const cv::FileNode& node, const std::string& file, const char* key) {
  const cv::FileNode data = node["data"];
  if (!data.isSeq()) return fail(fmt::format("{}: key '{}' is not a matrix (no data list)", file, key));
  cv::Mat m(static_cast<int>(data.size()), 1, CV_64F);
  for (int i = 0; i < m.rows; ++i) {
    const cv::FileNode v = data[i];
    if (!v.isReal() && !v.isInt()) return fail(fmt::format("{}: key '{}': data entry {} is not a number", file, key, i));
    m.at<double>(i) = static_cast<double>(v);
  }
  const cv::FileNode rows = node["rows"], cols = node["cols"];
  if (rows.isInt() && cols.isInt() && static_cast<int>(rows) * static_cast<int>(cols) != m.rows)
    return fail(fmt::format("{}: key '{}': {} x {} matrix with {} data entries", file, key, static_cast<int>(rows),
                            static_cast<int>(cols), m.rows));
  return m;
}

Result<cv::Mat> read_matrix(const cv::FileStorage& fs, const std::string& file,
                            const char* key, bool required) {
  const cv::FileNode node = fs[key];
  if (node.empty()) {
    if (!required) return cv::Mat();
    return fail(fmt::format("{}: missing key '{}'", file, key));
  }
  if (node.isMap() && node["dt"].empty()) return read_untagged_matrix(node, file, key);
  // OpenCV allocates rows x cols before it reads the data: a damaged size must not ask for
  // gigabytes. A calibration's matrices have at most 18 entries (calibrateCamera's
  // intrinsics_std_deviations).
  constexpr long long kMostEntries = 64;
  if (node.isMap()) {
    const cv::FileNode rows = node["rows"], cols = node["cols"];
    if (!rows.isInt() || !cols.isInt() || static_cast<int>(rows) < 1 || static_cast<int>(cols) < 1 ||
        static_cast<long long>(static_cast<int>(rows)) * static_cast<int>(cols) > kMostEntries)
      return fail(fmt::format("{}: key '{}': rows and cols must be whole numbers, at least 1, with at most {} "
                              "entries in all", file, key, kMostEntries));
  }
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception& e) {
    return fail(fmt::format("{}: key '{}' is not a matrix: {}", file, key, e.what()));
  }
  if (m.empty()) return fail(fmt::format("{}: key '{}' is not a matrix", file, key));
  m.convertTo(m, CV_64F);
  return m.reshape(1, static_cast<int>(m.total()));  // one column, row-major order
}

Result<int> read_positive_int(const cv::FileStorage& fs, const std::string& file,
                              const char* key) {
  const cv::FileNode node = fs[key];
  if (node.empty()) return fail(fmt::format("{}: missing key '{}'", file, key));
  if (!node.isInt()) return fail(fmt::format("{}: key '{}' is not an integer", file, key));
  const int v = static_cast<int>(node);
  if (v <= 0) return fail(fmt::format("{}: key '{}' must be positive, is {}", file, key, v));
  // Views and renders allocate an image of this size: a damaged value must not ask for
  // terabytes. 16384 px is twice an 8K sensor's width.
  constexpr int kLargestSide_px = 16384;
  if (v > kLargestSide_px)
    return fail(fmt::format("{}: key '{}' is {} px, more than the {} px covtrack accepts", file, key, v, kLargestSide_px));
  return v;
}

// The file's text, checked (calibration_text.hpp), and the format OpenCV is to read it
// as. OpenCV's YAML reader wants its "%YAML:1.0" first line, which ROS's camera_info files
// (camera_calibration_parsers) do not have: such a file is read with the line added.
struct CalibrationText {
  std::string text;
  int format = cv::FileStorage::FORMAT_AUTO;
};

Result<CalibrationText> read_calibration_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  // As much as the file holds, up to one byte more than a calibration may (a longer file
  // is refused), instead of a zeroed megabyte for a file of a few kilobytes.
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  CalibrationText c{std::string(ec ? kMostCalibrationBytes + 1 : std::min<std::uintmax_t>(size, kMostCalibrationBytes + 1), '\0')};
  in.read(c.text.data(), static_cast<std::streamsize>(c.text.size()));
  c.text.resize(static_cast<std::size_t>(in.gcount()));
  if (in.bad()) return fail(fmt::format("{}: cannot read", path.string()));
  if (auto checked = check_calibration_text(c.text); !checked)
    return fail(fmt::format("{}: not a calibration file: {}", path.string(), checked.error().message));
  if (const auto ext = path.extension().string(); ext == ".yaml" || ext == ".yml") {
    if (!c.text.starts_with("%YAML")) c.text = "%YAML:1.0\n---\n" + c.text;
    c.format = cv::FileStorage::FORMAT_YAML;
  } else if (ext == ".xml") {
    c.format = cv::FileStorage::FORMAT_XML;
  }
  return c;
}

// The camera from an opened file whose top level is a map (load_camera catches what
// OpenCV throws).
Result<Camera> read_camera(const cv::FileStorage& fs, const std::string& file) {
  // ROS names its lens model; only the one covtrack computes (OpenCV's k1 k2 p1 p2 k3) is taken.
  if (const cv::FileNode model = fs["distortion_model"]; !model.empty()) {
    const std::string name = model.isString() ? static_cast<std::string>(model) : std::string("?");
    if (name != "plumb_bob" && name != "rational_polynomial")
      return fail(fmt::format("{}: distortion_model '{}' is not supported (plumb_bob or rational_polynomial with "
                              "only k1 k2 p1 p2 k3 non-zero)", file, name));
  }

  Camera cam;
  auto width = read_positive_int(fs, file, "image_width");
  if (!width) return std::unexpected(width.error());
  auto height = read_positive_int(fs, file, "image_height");
  if (!height) return std::unexpected(height.error());
  cam.width_px = *width;
  cam.height_px = *height;

  auto K = read_matrix(fs, file, "camera_matrix", true);
  if (!K) return std::unexpected(K.error());
  if (K->total() != 9) return fail(fmt::format("{}: key 'camera_matrix' must be 3x3", file));
  const auto k = [&](int i) { return K->at<double>(i); };
  cam.fx = k(0), cam.cx = k(2), cam.fy = k(4), cam.cy = k(5);
  if (!(cam.fx > 0 && cam.fy > 0) || k(1) != 0 || k(3) != 0 || k(6) != 0 || k(7) != 0 ||
      k(8) != 1 || !std::isfinite(cam.fx) || !std::isfinite(cam.fy) || !std::isfinite(cam.cx) ||
      !std::isfinite(cam.cy))
    return fail(fmt::format(
        "{}: key 'camera_matrix' is not a pinhole matrix [fx 0 cx; 0 fy cy; 0 0 1]", file));

  auto dist = read_matrix(fs, file, "distortion_coefficients", true);
  if (!dist) return std::unexpected(dist.error());
  const int n = static_cast<int>(dist->total());
  if (n > 0 && n < 4)  // none (ROS writes an empty list for an undistorted camera), or k1 k2 p1 p2 [k3 ...]
    return fail(fmt::format("{}: key 'distortion_coefficients' needs 4 or 5 values, has {}",
                            file, n));
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(dist->at<double>(i)))
      return fail(fmt::format("{}: key 'distortion_coefficients': coefficient {} is not finite", file, i));
  for (int i = 5; i < n; ++i)
    if (dist->at<double>(i) != 0)
      return fail(fmt::format(
          "{}: key 'distortion_coefficients': only k1 k2 p1 p2 k3 are supported, "
          "coefficient {} is non-zero",
          file, i));
  const auto coefficient = [&](int i) { return i < n ? dist->at<double>(i) : 0.0; };
  cam.k1 = coefficient(0), cam.k2 = coefficient(1), cam.p1 = coefficient(2), cam.p2 = coefficient(3);
  cam.k3 = coefficient(4);

  auto sig = read_matrix(fs, file, "intrinsics_std_deviations", false);
  if (!sig) return std::unexpected(sig.error());
  if (!sig->empty()) {
    if (sig->total() < 4)
      return fail(fmt::format("{}: key 'intrinsics_std_deviations' needs fx fy cx cy", file));
    // Each becomes a variance of every projected pixel: a NaN or a negative one is a
    // damaged file, to be named here rather than found as NaN regions.
    constexpr const char* kNames[4] = {"fx", "fy", "cx", "cy"};
    for (int i = 0; i < 4; ++i) {
      const double sigma = sig->at<double>(i);
      if (!(std::isfinite(sigma) && sigma >= 0))
        return fail(fmt::format("{}: key 'intrinsics_std_deviations': {} is {}, not a standard deviation (finite, 0 or more)",
                                file, kNames[i], sigma));
      cam.intrinsic_sigmas_px[i] = sigma;
    }
  }
  return cam;
}

// OpenCV's reading of the text, in the child process of read_isolated. OpenCV throws on
// malformed text, and on a key looked up in a top level that is not a map of keys (a
// YAML list, a second document): each becomes an error value.
Result<Camera> parse_calibration(const CalibrationText& c, const std::string& file) {
  try {
    cv::FileStorage fs;
    if (!fs.open(c.text, cv::FileStorage::READ | cv::FileStorage::MEMORY | c.format))
      return fail(fmt::format("{}: cannot open as an OpenCV or ROS camera_info calibration file", file));
    if (!fs.root().isMap())
      return fail(fmt::format("{}: not a calibration file: its top level is not a map of keys", file));
    return read_camera(fs, file);
  } catch (const cv::Exception& e) {
    return fail(fmt::format("{}: not a readable OpenCV or ROS camera_info calibration file: {}", file, e.what()));
  }
}

}  // namespace

Result<Camera> load_camera(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return fail(fmt::format("{}: calibration file not found", file));
  const auto text = read_calibration_text(path);
  if (!text) return std::unexpected(text.error());
  return read_isolated([&] { return parse_calibration(*text, file); }, file);
}

Result<void> save_camera(const Camera& camera, const std::filesystem::path& path) {
  try {
    cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
    if (!fs.isOpened()) return fail(fmt::format("{}: cannot write", path.string()));
    fs << "image_width" << camera.width_px << "image_height" << camera.height_px;
    fs << "camera_matrix" << cv::Mat(camera_matrix(camera));
    fs << "distortion_coefficients" << distortion_vector(camera);
    if (!camera.intrinsic_sigmas_px.isZero())
      fs << "intrinsics_std_deviations"
         << cv::Mat(cv::Vec4d(camera.intrinsic_sigmas_px[0], camera.intrinsic_sigmas_px[1],
                              camera.intrinsic_sigmas_px[2], camera.intrinsic_sigmas_px[3]));
  } catch (const cv::Exception& e) {
    return fail(fmt::format("{}: cannot write: {}", path.string(), e.what()));
  }
  return {};
}

}  // namespace covtrack
