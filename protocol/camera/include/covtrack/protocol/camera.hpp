#pragma once
// A pinhole camera with OpenCV's 5-coefficient distortion model (k1 k2 p1 p2 k3).
// Camera frame as in OpenCV: looks along +z, x right, y down; pixels (u, v) from the
// top-left corner. Loaded from the file OpenCV's calibration sample writes.
// The one camera model of covtrack: the client's screen regions and the fiducial tracker
// (devices/fiducial, which adds OpenCV's K matrix and distortion vector forms) use it.
#include <filesystem>

#include <Eigen/Core>

#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;
using Mat23 = Eigen::Matrix<double, 2, 3>;

struct Camera {
  double fx = 0, fy = 0, cx = 0, cy = 0;  // px
  int width_px = 0, height_px = 0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  // Standard deviations of (fx, fy, cx, cy) in px; zero when the calibration gives none.
  Eigen::Vector4d intrinsic_sigmas_px = Eigen::Vector4d::Zero();

  bool has_distortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }

  // Pixel of a point in the camera frame (z > 0 expected; the caller checks depth).
  // J_pixel_point, if given, receives d(pixel)/d(p_camera), exact, distortion included.
  Vec2 project(const Vec3& p_camera, Mat23* J_pixel_point = nullptr) const;

  // The pixel of normalised coordinates (x, y) = (X/Z, Y/Z), distortion included. Inline,
  // so that a loop over many points (the unscented projection) vectorises.
  void pixel_of_normalised(double x, double y, double& u, double& v) const {
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    u = fx * (x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x)) + cx;
    v = fy * (y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y) + cy;
  }
  // The same and d(u, v)/d(x, y), row-major, exact (distortion included).
  void pixel_of_normalised(double x, double y, double& u, double& v, double (&d)[4]) const {
    pixel_of_normalised(x, y, u, v);
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial_dr2 = k1 + r2 * (2 * k2 + 3 * k3 * r2);
    const double drad_dx = 2 * x * dradial_dr2, drad_dy = 2 * y * dradial_dr2;
    d[0] = fx * (radial + x * drad_dx + 2 * p1 * y + 6 * p2 * x);
    d[1] = fx * (x * drad_dy + 2 * p1 * x + 2 * p2 * y);
    d[2] = fy * (y * drad_dx + 2 * p1 * x + 2 * p2 * y);
    d[3] = fy * (radial + y * drad_dy + 6 * p1 * y + 2 * p2 * x);
  }

  // Where the radial distortion folds back: the smallest r^2 = x^2 + y^2 (normalised) at
  // which the distorted radius r (1 + k1 r^2 + k2 r^4 + k3 r^6) stops growing with r.
  // Points beyond it land back inside the image at a wrong pixel. Infinity when the
  // model never folds (tangential terms are small there and left out).
  double distortion_fold_r2() const;

  // First-order screen covariance (px^2) due to the intrinsic sigmas, at this point.
  Mat2 intrinsic_covariance(const Vec3& p_camera) const { return intrinsic_covariance_at(project(p_camera)); }
  // The same from the point's pixel (it depends on nothing else).
  Mat2 intrinsic_covariance_at(const Vec2& pixel) const;
};

// Reads `camera_matrix`, `distortion_coefficients` (4 or 5 values, or none; longer
// vectors only if the extra terms are zero), `image_width`, `image_height`, and the
// optional `intrinsics_std_deviations` (fx fy cx cy first, as cv::calibrateCamera orders
// them). Two layouts: OpenCV's (cv::FileStorage YAML, XML or JSON, as its calibration
// sample writes; XML by the name's .xml or, for a name that is not .yml or .yaml, by a
// first character '<') and ROS's camera_info YAML (camera_calibration_parsers: untagged {rows, cols,
// data} matrices, `distortion_model` plumb_bob or rational_polynomial; the rectification
// and projection matrices, for stereo, are not used). Errors name the file and the key.
// A damaged file is an error, never a hang or a crash: the text is checked first (at most
// 1 MiB, nested at most 32 deep), then read by yaml-cpp or tinyxml2 (not OpenCV, whose
// reader loops forever on some malformed YAML). A key given twice is an error.
Result<Camera> load_camera(const std::filesystem::path& file);

// Writes `camera` in OpenCV's layout, which load_camera reads back (the fiducial renderer
// writes its emulated camera so). The sigmas are written only when there are some.
Result<void> save_camera(const Camera& camera, const std::filesystem::path& file);

}  // namespace covtrack
