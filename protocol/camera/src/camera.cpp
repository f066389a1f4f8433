#include "covtrack/protocol/camera.hpp"
#include "covtrack/protocol/camera_opencv.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "calibration_entries.hpp"
#include "calibration_text.hpp"

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

// The whole of `text` as a T, a leading '+' allowed; nullopt for anything else.
template <class T>
std::optional<T> parsed(std::string_view text) {
  if (text.starts_with('+') && !text.substr(1).starts_with('-')) text.remove_prefix(1);
  T v{};
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return v;
}

// Numbers as YAML and OpenCV write them: "640", "5.0e+02", "1." and YAML's .nan, .inf.
std::optional<double> number_of(std::string_view text) {
  const auto is = [&](std::string_view name) {
    return std::ranges::equal(text, name, [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
  };
  if (is(".nan")) return std::numeric_limits<double>::quiet_NaN();
  if (is(".inf") || is("+.inf")) return std::numeric_limits<double>::infinity();
  if (is("-.inf")) return -std::numeric_limits<double>::infinity();
  return parsed<double>(text);
}

std::optional<long long> whole_number_of(std::string_view text) { return parsed<long long>(text); }

// Values per element from OpenCV's dt ("d", "f", "3d", ...): its leading count, or 1.
std::optional<long long> channels_of(std::string_view dt) {
  const auto letters = dt.find_first_not_of("0123456789");
  if (letters == std::string_view::npos || dt.size() - letters != 1 ||
      std::string_view("ucwsifdh").find(dt[letters]) == std::string_view::npos)
    return std::nullopt;
  if (letters == 0) return 1;
  const auto count = whole_number_of(dt.substr(0, letters));
  if (!count || *count < 1 || *count > 4) return std::nullopt;
  return count;
}

// A matrix's entries in row-major order: an OpenCV matrix ({rows, cols, dt, data}) or a
// ROS camera_info one (no dt; rows and cols are checked where both are given). Empty for
// a key that is not required and not there.
Result<std::vector<double>> read_matrix(const CalibrationEntries& entries, const std::string& file, const char* key,
                                        bool required) {
  const auto it = entries.find(key);
  if (it == entries.end()) {
    if (!required) return std::vector<double>{};
    return fail(fmt::format("{}: missing key '{}'", file, key));
  }
  const CalibrationValue& value = it->second;
  if (value.kind != CalibrationValue::Kind::matrix)
    return fail(fmt::format("{}: key '{}' is not a matrix (rows, cols and a data list)", file, key));
  std::vector<double> data;
  for (std::size_t i = 0; i < value.data.size(); ++i) {
    const auto v = number_of(value.data[i]);
    if (!v) return fail(fmt::format("{}: key '{}': data entry {} is not a number", file, key, i));
    data.push_back(*v);
  }
  // -1 where a size is missing or not a whole number.
  const long long rows = value.rows ? whole_number_of(*value.rows).value_or(-1) : -1;
  const long long cols = value.cols ? whole_number_of(*value.cols).value_or(-1) : -1;
  long long per_element = 1;
  if (value.dt) {
    // An OpenCV matrix: its size is part of it. A calibration's matrices have at most 18
    // entries (calibrateCamera's intrinsics_std_deviations).
    constexpr long long kMostEntries = 64;
    if (rows < 1 || cols < 1 || rows > kMostEntries || cols > kMostEntries || rows * cols > kMostEntries)
      return fail(fmt::format("{}: key '{}': rows and cols must be whole numbers, at least 1, with at most {} "
                              "entries in all", file, key, kMostEntries));
    const auto channels = channels_of(*value.dt);
    if (!channels) return fail(fmt::format("{}: key '{}': dt '{}' is not an OpenCV element type", file, key, *value.dt));
    per_element = *channels;
  }
  // No data list has as many entries as the text has bytes: a size past that cannot
  // match, and is not multiplied (where it could overflow).
  constexpr auto kLonger = static_cast<long long>(kMostCalibrationBytes);
  if (rows >= 0 && cols >= 0 &&
      (rows > kLonger || cols > kLonger || rows * cols * per_element != static_cast<long long>(data.size())))
    return fail(fmt::format("{}: key '{}': {} x {} matrix with {} data entries", file, key, rows, cols, data.size()));
  return data;
}

Result<int> read_positive_int(const CalibrationEntries& entries, const std::string& file, const char* key) {
  const auto it = entries.find(key);
  if (it == entries.end()) return fail(fmt::format("{}: missing key '{}'", file, key));
  const auto v = it->second.kind == CalibrationValue::Kind::text ? whole_number_of(it->second.text) : std::nullopt;
  if (!v) return fail(fmt::format("{}: key '{}' is not an integer", file, key));
  if (*v <= 0) return fail(fmt::format("{}: key '{}' must be positive, is {}", file, key, *v));
  // Views and renders allocate an image of this size: a damaged value must not ask for
  // terabytes. 16384 px is twice an 8K sensor's width.
  constexpr int kLargestSide_px = 16384;
  if (*v > kLargestSide_px)
    return fail(fmt::format("{}: key '{}' is {} px, more than the {} px covtrack accepts", file, key, *v, kLargestSide_px));
  return static_cast<int>(*v);
}

// The file's entries: its text checked (calibration_text.hpp), then read as XML where
// its name says so or, with another name, where it starts with '<'; else as YAML.
Result<CalibrationEntries> read_calibration_entries(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  // As much as the file holds, up to one byte more than a calibration may (a longer file
  // is refused), instead of a zeroed megabyte for a file of a few kilobytes.
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  std::string text(ec ? kMostCalibrationBytes + 1 : std::min<std::uintmax_t>(size, kMostCalibrationBytes + 1), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (in.bad()) return fail(fmt::format("{}: cannot read", path.string()));
  const auto not_calibration = [&](const Error& e) {
    return fail(fmt::format("{}: not a calibration file: {}", path.string(), e.message));
  };
  if (const auto checked = check_calibration_text(text); !checked) return not_calibration(checked.error());
  const auto ext = path.extension().string();
  const auto first = text.find_first_not_of(" \t\r\n");
  const bool xml = ext == ".xml" || (ext != ".yml" && ext != ".yaml" && first != std::string::npos && text[first] == '<');
  auto entries = xml ? read_xml_entries(text) : read_yaml_entries(text);
  if (!entries) return not_calibration(entries.error());
  return entries;
}

}  // namespace

Result<Camera> load_camera(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return fail(fmt::format("{}: calibration file not found", file));
  const auto read = read_calibration_entries(path);
  if (!read) return std::unexpected(read.error());
  const CalibrationEntries& entries = *read;

  // ROS names its lens model; only the one covtrack computes (OpenCV's k1 k2 p1 p2 k3) is taken.
  if (const auto model = entries.find("distortion_model"); model != entries.end()) {
    const std::string name = model->second.kind == CalibrationValue::Kind::text ? model->second.text : "?";
    if (name != "plumb_bob" && name != "rational_polynomial")
      return fail(fmt::format("{}: distortion_model '{}' is not supported (plumb_bob or rational_polynomial with "
                              "only k1 k2 p1 p2 k3 non-zero)", file, name));
  }

  Camera cam;
  auto width = read_positive_int(entries, file, "image_width");
  if (!width) return std::unexpected(width.error());
  auto height = read_positive_int(entries, file, "image_height");
  if (!height) return std::unexpected(height.error());
  cam.width_px = *width;
  cam.height_px = *height;

  auto K = read_matrix(entries, file, "camera_matrix", true);
  if (!K) return std::unexpected(K.error());
  if (K->size() != 9) return fail(fmt::format("{}: key 'camera_matrix' must be 3x3", file));
  const auto k = [&](int i) { return (*K)[i]; };
  cam.fx = k(0), cam.cx = k(2), cam.fy = k(4), cam.cy = k(5);
  if (!(cam.fx > 0 && cam.fy > 0) || k(1) != 0 || k(3) != 0 || k(6) != 0 || k(7) != 0 ||
      k(8) != 1 || !std::isfinite(cam.fx) || !std::isfinite(cam.fy) || !std::isfinite(cam.cx) ||
      !std::isfinite(cam.cy))
    return fail(fmt::format(
        "{}: key 'camera_matrix' is not a pinhole matrix [fx 0 cx; 0 fy cy; 0 0 1]", file));

  auto dist = read_matrix(entries, file, "distortion_coefficients", true);
  if (!dist) return std::unexpected(dist.error());
  const int n = static_cast<int>(dist->size());
  if (n > 0 && n < 4)  // none (ROS writes an empty list for an undistorted camera), or k1 k2 p1 p2 [k3 ...]
    return fail(fmt::format("{}: key 'distortion_coefficients' needs 4 or 5 values, has {}",
                            file, n));
  // No lens has a coefficient near this bound (they are of order 1, a fisheye's in the
  // tens); beyond it, the projection's derivatives overflow to infinity (a fuzzed file
  // with k3 = -3e301 gave an infinite intrinsic covariance).
  constexpr double kMaxCoefficient = 1e6;
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite((*dist)[i]))
      return fail(fmt::format("{}: key 'distortion_coefficients': coefficient {} is not finite", file, i));
    if (std::abs((*dist)[i]) > kMaxCoefficient)
      return fail(fmt::format("{}: key 'distortion_coefficients': coefficient {} is {}, beyond any lens (at most {:g} "
                              "either way)",
                              file, i, (*dist)[i], kMaxCoefficient));
  }
  for (int i = 5; i < n; ++i)
    if ((*dist)[i] != 0)
      return fail(fmt::format(
          "{}: key 'distortion_coefficients': only k1 k2 p1 p2 k3 are supported, "
          "coefficient {} is non-zero",
          file, i));
  const auto coefficient = [&](int i) { return i < n ? (*dist)[i] : 0.0; };
  cam.k1 = coefficient(0), cam.k2 = coefficient(1), cam.p1 = coefficient(2), cam.p2 = coefficient(3);
  cam.k3 = coefficient(4);

  auto sig = read_matrix(entries, file, "intrinsics_std_deviations", false);
  if (!sig) return std::unexpected(sig.error());
  if (!sig->empty()) {
    if (sig->size() < 4)
      return fail(fmt::format("{}: key 'intrinsics_std_deviations' needs fx fy cx cy", file));
    // Each becomes a variance of every projected pixel: a NaN or a negative one is a
    // damaged file, to be named here rather than found as NaN regions.
    constexpr const char* kNames[4] = {"fx", "fy", "cx", "cy"};
    for (int i = 0; i < 4; ++i) {
      const double sigma = (*sig)[i];
      if (!(std::isfinite(sigma) && sigma >= 0))
        return fail(fmt::format("{}: key 'intrinsics_std_deviations': {} is {}, not a standard deviation (finite, 0 or more)",
                                file, kNames[i], sigma));
      cam.intrinsic_sigmas_px[i] = sigma;
    }
  }
  return cam;
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
