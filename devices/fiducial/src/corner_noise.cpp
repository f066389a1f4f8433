#include "covtrack/devices/fiducial/corner_noise.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <opencv2/imgproc.hpp>

namespace covtrack::fiducial {

double CornerNoiseModel::noise_term(double image_noise, double contrast, double edge_length_px) {
  const double ratio = image_noise / std::max(contrast, 1.0);
  return ratio * ratio * 16.0 / std::max(16.0, edge_length_px / 8.0);
}

double CornerNoiseModel::sigma_px(double image_noise, double contrast, double edge_length_px,
                                  double axis_alignment) const {
  return std::sqrt(floor_px * floor_px +
                   gain_px * gain_px * noise_term(image_noise, contrast, edge_length_px) +
                   aligned_px * aligned_px * axis_alignment);
}

double CornerNoiseModel::narrow_sigma_px(double quiet_band_px) const {
  if (narrow_px <= 0) return 0;
  // A degenerate quad (NaN band) counts as the narrowest band: never less variance.
  const double band = quiet_band_px > 0.5 ? quiet_band_px : 0.5;
  return narrow_px * std::pow(kNarrowBandPx / band, narrow_power / 2);
}

std::array<double, 4> CornerNoiseModel::narrow_sigmas_px(const std::array<double, 4>& corner_band_px) const {
  std::array<double, 4> sigmas{};
  for (std::size_t k = 0; k < 4; ++k) sigmas[k] = narrow_sigma_px(corner_band_px[k]);
  return sigmas;
}

double estimate_image_noise(const cv::Mat& gray) {
  CV_Assert(gray.type() == CV_8UC1);
  // The filter [1 -2 1; -2 4 -2; 1 -2 1] cancels any locally planar image and leaves
  // 6 sigma of white noise in its standard deviation; a median needs no edge mask.
  // Responses are integers in [0, 16 * 255]: a histogram gives the exact median without
  // storing or partially sorting them (that was most of this function's time).
  constexpr int kStep = 3;
  constexpr int kMaxResponse = 16 * 255;
  std::array<std::uint32_t, kMaxResponse + 1> counts{};
  std::uint32_t n = 0;
  for (int r = 1; r + 1 < gray.rows; r += kStep) {
    const std::uint8_t* a = gray.ptr<std::uint8_t>(r - 1);
    const std::uint8_t* b = gray.ptr<std::uint8_t>(r);
    const std::uint8_t* c = gray.ptr<std::uint8_t>(r + 1);
    for (int x = 1; x + 1 < gray.cols; x += kStep) {
      const int v = a[x - 1] - 2 * a[x] + a[x + 1] - 2 * (b[x - 1] - 2 * b[x] + b[x + 1]) +
                    c[x - 1] - 2 * c[x] + c[x + 1];
      ++counts[static_cast<std::size_t>(std::abs(v))];
      ++n;
    }
  }
  if (n == 0) return 0;
  // The element a sort would put at index n / 2.
  std::uint32_t seen = 0;
  int median = 0;
  while ((seen += counts[static_cast<std::size_t>(median)]) <= n / 2) ++median;
  // For Gaussian noise the median of |N(0, 36 sigma^2)| is 0.6745 * 6 sigma.
  return median / (0.6745 * 6.0);
}

namespace {
double sample(const cv::Mat& gray, cv::Point2d p) {
  const int x = static_cast<int>(std::floor(p.x)), y = static_cast<int>(std::floor(p.y));
  if (x < 0 || y < 0 || x + 1 >= gray.cols || y + 1 >= gray.rows) return std::nan("");
  const double fx = p.x - x, fy = p.y - y;
  const auto at = [&](int yy, int xx) { return static_cast<double>(gray.at<std::uint8_t>(yy, xx)); };
  return (1 - fy) * ((1 - fx) * at(y, x) + fx * at(y, x + 1)) +
         fy * ((1 - fx) * at(y + 1, x) + fx * at(y + 1, x + 1));
}
}  // namespace

double tag_contrast(const cv::Mat& gray, const std::array<cv::Point2d, 4>& c,
                    int cells_across_border) {
  cv::Point2d centre(0, 0);
  for (const auto& p : c) centre += p / 4.0;
  double sum = 0;
  int n = 0;
  for (int e = 0; e < 4; ++e) {
    const cv::Point2d a = c[e], b = c[(e + 1) % 4];
    for (double f : {0.25, 0.5, 0.75}) {
      const cv::Point2d on = a + f * (b - a);
      // Half a cell towards the centre and away from it (a cell is the edge / cells).
      const cv::Point2d towards_centre = centre - on;
      const double to_centre = std::hypot(towards_centre.x, towards_centre.y);
      if (to_centre <= 0) continue;
      const double half_cell = 0.5 * std::hypot(b.x - a.x, b.y - a.y) / cells_across_border;
      const cv::Point2d step = towards_centre * (half_cell / to_centre);
      const double in = sample(gray, on + step), out = sample(gray, on - step);
      if (std::isnan(in) || std::isnan(out)) continue;
      sum += std::abs(out - in);
      ++n;
    }
  }
  return n ? sum / n : 0;
}

double edge_axis_alignment(const std::array<cv::Point2d, 4>& c) {
  constexpr double kWidthRad = 3.0 * M_PI / 180;
  double sum = 0;
  for (int e = 0; e < 4; ++e) {
    const cv::Point2d d = c[(e + 1) % 4] - c[e];
    // Angle to the nearest pixel axis, in [0, 45 deg].
    double a = std::fmod(std::abs(std::atan2(d.y, d.x)), M_PI / 2);
    a = std::min(a, M_PI / 2 - a);
    sum += std::exp(-(a / kWidthRad) * (a / kWidthRad));
  }
  return sum / 4;
}

double mean_edge_length_px(const std::array<cv::Point2d, 4>& c) {
  double sum = 0;
  for (int e = 0; e < 4; ++e) sum += std::hypot(c[(e + 1) % 4].x - c[e].x, c[(e + 1) % 4].y - c[e].y);
  return sum / 4;
}

std::array<double, 4> quiet_band_px(const std::array<cv::Point2d, 4>& c, int cells_across_border,
                                    double quiet_cells) {
  // The detected square as [-1, 1]^2 in AprilTag's corner order; a cell is 2 / cells wide.
  const cv::Point2f plane[4] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
  const cv::Point2f image[4] = {c[0], c[1], c[2], c[3]};
  const cv::Matx33d H(cv::getPerspectiveTransform(plane, image));
  const double out = 1 + 2 * quiet_cells / std::max(cells_across_border, 1);
  std::array<double, 4> band{};
  for (int e = 0; e < 4; ++e) {
    const cv::Point2d a = c[e], b = c[(e + 1) % 4];
    const cv::Vec3d m = H * cv::Vec3d(out * (plane[e].x + plane[(e + 1) % 4].x) / 2,
                                      out * (plane[e].y + plane[(e + 1) % 4].y) / 2, 1);
    const cv::Point2d p(m[0] / m[2], m[1] / m[2]);
    const double length = std::max(std::hypot(b.x - a.x, b.y - a.y), 1e-9);
    band[static_cast<std::size_t>(e)] = std::abs((b - a).cross(p - a)) / length;
  }
  return band;
}

std::array<double, 4> corner_quiet_band_px(const std::array<cv::Point2d, 4>& c,
                                           int cells_across_border, double quiet_cells) {
  const auto edge = quiet_band_px(c, cells_across_border, quiet_cells);
  std::array<double, 4> corner{};
  for (std::size_t k = 0; k < 4; ++k) corner[k] = std::min(edge[(k + 3) % 4], edge[k]);
  return corner;
}

}  // namespace covtrack::fiducial
