#include "corner_noise.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace covtrack::fiducial {

namespace {
// An edge's turn stays locked over more drift than its placement (corner_noise.hpp): the
// calibration's locked views under-model turns 2.4-3.2x at 0.5-2 px of drift with the
// placement's 0.5 px, 1.2-1.7x with 1.5 px, and nothing beyond 2 px.
constexpr double kTurnLockPx = 1.5;
}  // namespace

double CornerNoiseModel::sample_factor(double edge_length_px) {
  // AprilTag 3's refine_edges samples each edge at max(16, L / 8) points.
  return 16.0 / std::max(16.0, edge_length_px / 8.0);
}

double CornerNoiseModel::size_factor(double edge_length_px) {
  // Under 16 px AprilTag rarely decodes a tag; the floor keeps a degenerate length finite.
  return 64.0 / std::max(16.0, edge_length_px);
}

double CornerNoiseModel::noise_term(double image_noise, double contrast, double edge_length_px) {
  const double ratio = image_noise / std::max(contrast, 1.0);
  return ratio * ratio * sample_factor(edge_length_px);
}

std::array<double, 4> CornerNoiseModel::edge_reach(const CornerInputs& in) const {
  std::array<double, 4> reach{};
  // An unmeasured blur (no slope found) counts as wide: never less variance.
  const double blur = std::isfinite(in.blur_px) && in.blur_px > 0 ? in.blur_px : 1e9;
  for (std::size_t e = 0; e < 4; ++e) {
    const double x = std::isfinite(in.border_px[e]) ? in.border_px[e] / blur : 0;
    reach[e] = std::exp(-shift_falloff * x * x);
  }
  return reach;
}

namespace {
// An unmeasured blur (no slope found) gets no growth term; the floor still applies.
double blur_or_zero(const CornerInputs& in) {
  return std::isfinite(in.blur_px) && in.blur_px > 0 ? in.blur_px : 0;
}
}  // namespace

EdgeShifts CornerNoiseModel::edge_shift_px(const CornerInputs& in) const {
  const auto reach = edge_reach(in);
  const double common = in.polarity * scale_bias_per_blur * blur_or_zero(in);
  EdgeShifts shift{};
  for (std::size_t e = 0; e < 4; ++e)
    for (std::size_t end = 0; end < 2; ++end)
      shift[e][end] = shift_px * reach[e] * in.inner_white[e][end] + common;
  return shift;
}

double CornerNoiseModel::sigma_px(const CornerInputs& in) const {
  return std::sqrt(floor_px * floor_px + aligned_px * aligned_px * in.axis_alignment);
}

double CornerNoiseModel::line_sigma(const CornerInputs& in) const {
  return std::sqrt(sample_floor_px * sample_floor_px * sample_factor(in.edge_length_px) +
                   gain_px * gain_px * noise_term(in.image_noise, in.contrast, in.edge_length_px));
}

double CornerNoiseModel::scale_sigma(const CornerInputs& in) const {
  return std::hypot(scale_sigma_px, scale_per_blur * blur_or_zero(in));
}

double CornerNoiseModel::edge_sigma(const CornerInputs& in) const {
  return std::hypot(edge_sigma_px, edge_per_blur * blur_or_zero(in)) * size_factor(in.edge_length_px);
}

double CornerNoiseModel::tilt_sigma(const CornerInputs& in) const {
  return std::hypot(tilt_sigma_px, tilt_per_blur * blur_or_zero(in)) * size_factor(in.edge_length_px);
}

CornerNoise CornerNoiseModel::noise(const CornerInputs& in) const {
  CornerNoise out;
  out.sigma_px = sigma_px(in);
  out.line_sigma_px = line_sigma(in);
  out.scale_sigma_px = scale_sigma(in);
  out.edge_sigma_px = edge_sigma(in);
  out.tilt_sigma_px = tilt_sigma(in);
  out.edge_shift_px = edge_shift_px(in);
  const auto reach = edge_reach(in);
  // Corner k joins edges k - 1 and k.
  for (std::size_t k = 0; k < 4; ++k)
    out.extra_px[k] = shift_sigma_px * std::hypot(reach[(k + 3) % 4], reach[k]);
  for (std::size_t e = 0; e < 4; ++e) {
    out.locked_edge_px[e] = locked_edge_px * std::sqrt(in.phase_lock[e]);
    out.locked_tilt_px[e] = locked_tilt_px * std::sqrt(in.turn_lock[e]);
  }
  return out;
}

CornerInputs measure_corner_inputs(const cv::Mat& gray, const Detection& d, const TagFamily& family,
                                   double image_noise) {
  CornerInputs in;
  const int cells = family.cells_across_border();
  in.contrast = tag_contrast(gray, d.corners_px, cells);
  in.edge_length_px = mean_edge_length_px(d.corners_px);
  in.axis_alignment = edge_axis_alignment(d.corners_px);
  in.phase_lock = edge_phase_lock(d.corners_px);
  in.turn_lock = edge_phase_lock(d.corners_px, kTurnLockPx);
  in.blur_px = edge_blur_px(gray, d.corners_px, in.contrast);
  in.border_px = border_width_px(d.corners_px, cells);
  // The edge fit's samples straddle both sides of the edge: the mean of their variances.
  constexpr double kFrameWeight = 32;  // in responses (see the header)
  const auto variance = [&](const RingNoise& ring) {
    if (!std::isfinite(ring.sigma)) return image_noise * image_noise;
    const double n = static_cast<double>(ring.responses);
    return (n * ring.sigma * ring.sigma + kFrameWeight * image_noise * image_noise) / (n + kFrameWeight);
  };
  in.image_noise = std::sqrt((variance(ring_noise(gray, d.corners_px, in.border_px, false)) +
                              variance(ring_noise(gray, d.corners_px, in.border_px, true))) / 2);
  in.inner_white = family.border_inner_white(d.id);
  in.polarity = family.reversed_border() ? -1 : 1;
  return in;
}

namespace {
// The sum of the 2x2 pixels whose top-left one is (x, y): the scale both noise measures
// read at (see estimate_image_noise).
int block_sum(const cv::Mat& gray, int x, int y) {
  const std::uint8_t* a = gray.ptr<std::uint8_t>(y) + x;
  const std::uint8_t* b = gray.ptr<std::uint8_t>(y + 1) + x;
  return a[0] + a[1] + b[0] + b[1];
}
}  // namespace

double estimate_image_noise(const cv::Mat& gray) {
  CV_Assert(gray.type() == CV_8UC1);
  // Measured on 2x2 block sums, not single pixels: JPEG removes most of a frame's
  // finest-scale noise (which a per-pixel filter sees) but keeps the coarser noise that
  // moves an edge fitted over several pixels. For white noise both scales give sigma.
  // The filter [1 -2 1; -2 4 -2; 1 -2 1] cancels any locally planar image and leaves
  // 6 sigma_sum = 12 sigma of white noise in its standard deviation; a median needs no
  // edge mask. Responses are integers in [0, 16 * 4 * 255]: a histogram gives the exact
  // median without storing or partially sorting them.
  constexpr int kStep = 2;  // in blocks
  constexpr int kMaxResponse = 16 * 4 * 255;
  std::vector<std::uint32_t> counts(kMaxResponse + 1, 0);
  const int block_rows = gray.rows / 2, block_cols = gray.cols / 2;
  const auto block = [&](int r, int c) { return block_sum(gray, 2 * c, 2 * r); };
  std::uint32_t n = 0;
  for (int r = 1; r + 1 < block_rows; r += kStep)
    for (int c = 1; c + 1 < block_cols; c += kStep) {
      const int v = block(r - 1, c - 1) - 2 * block(r - 1, c) + block(r - 1, c + 1) -
                    2 * (block(r, c - 1) - 2 * block(r, c) + block(r, c + 1)) + block(r + 1, c - 1) -
                    2 * block(r + 1, c) + block(r + 1, c + 1);
      ++counts[static_cast<std::size_t>(std::abs(v))];
      ++n;
    }
  if (n == 0) return 0;
  // The element a sort would put at index n / 2.
  std::uint32_t seen = 0;
  int median = 0;
  while ((seen += counts[static_cast<std::size_t>(median)]) <= n / 2) ++median;
  // For Gaussian noise the median of |N(0, 144 sigma^2)| is 0.6745 * 12 sigma.
  return median / (0.6745 * 12.0);
}

RingNoise ring_noise(const cv::Mat& gray, const std::array<cv::Point2d, 4>& c,
                     const std::array<double, 4>& border_px, bool outside) {
  CV_Assert(gray.type() == CV_8UC1);
  constexpr double kStep = 4.0;       // px: the larger axis step is >= 2.8, so blocks are disjoint
  constexpr double kMinBorder = 4.0;  // px: a 2x2 block in the middle of a thinner ring is mostly edge
  constexpr std::size_t kMinResponses = 16;
  const auto normal = edge_outward_normals(c);
  std::vector<int> responses;
  for (std::size_t e = 0; e < 4; ++e) {
    const double width = border_px[e];
    if (!(width >= kMinBorder)) continue;
    const cv::Point2d a = c[e], b = c[(e + 1) % 4];
    const double length = std::hypot(b.x - a.x, b.y - a.y);
    // No edge of a tag in the frame is longer than this; a corner far off it (or not a
    // number) must not make the walk below endless.
    if (!(length <= 2.0 * (gray.rows + gray.cols))) continue;
    const cv::Point2d along = (b - a) / std::max(length, 1e-9);
    // The ring's middle line, a border's width clear of each corner (where the
    // neighbouring edges' blur reaches in).
    const cv::Point2d start = a + normal[e] * (outside ? width / 2 : -width / 2) + along * width;
    int older = 0, old = 0, have = 0;  // the two blocks before this one, how many in a row
    for (double s = 0; s <= length - 2 * width; s += kStep) {
      const cv::Point2d p = start + along * s;
      // The 2x2 block whose centre is nearest p (pixel x covers [x - 0.5, x + 0.5]).
      const int x = static_cast<int>(std::floor(p.x)), y = static_cast<int>(std::floor(p.y));
      if (x < 0 || y < 0 || x + 1 >= gray.cols || y + 1 >= gray.rows) {
        have = 0;
        continue;
      }
      const int sum = block_sum(gray, x, y);
      if (have >= 2) responses.push_back(std::abs(older - 2 * old + sum));
      older = old, old = sum, ++have;
    }
  }
  if (responses.size() < kMinResponses) return {std::nan(""), responses.size()};
  // The median of whole numbers, interpolated within its unit: with a few dozen
  // responses of a few units each, the plain median would step by a sixth.
  std::sort(responses.begin(), responses.end());
  const double half = responses.size() / 2.0;
  const int median = responses[responses.size() / 2];
  const auto first = std::lower_bound(responses.begin(), responses.end(), median);
  const auto last = std::upper_bound(responses.begin(), responses.end(), median);
  const double interpolated = median - 0.5 + (half - static_cast<double>(first - responses.begin())) /
                                                 static_cast<double>(last - first);
  // Three disjoint block sums of white noise: the second difference has variance
  // (1 + 4 + 1) * 4 sigma^2; the median of its absolute value is 0.6745 of that's root.
  return {std::max(interpolated, 0.0) / (0.6745 * std::sqrt(24.0)), responses.size()};
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

double edge_blur_px(const cv::Mat& gray, const std::array<cv::Point2d, 4>& c, double contrast) {
  // Profiles across the four edges (away from the corners) averaged on a 0.25 px grid
  // along the outward normal, so that noise averages down before the slope is taken.
  constexpr int kHalf = 6;  // +-1.5 px: inside the black border and the quiet band
  constexpr double kStep = 0.25;
  std::array<double, 2 * kHalf + 1> profile{};
  std::array<int, 2 * kHalf + 1> count{};
  const auto normal = edge_outward_normals(c);
  for (int e = 0; e < 4; ++e) {
    const cv::Point2d a = c[e], b = c[(e + 1) % 4];
    if (std::hypot(b.x - a.x, b.y - a.y) <= 0) continue;
    const cv::Point2d n = normal[static_cast<std::size_t>(e)];
    for (double f = 0.2; f < 0.81; f += 0.1)
      for (int i = -kHalf; i <= kHalf; ++i) {
        const double g = sample(gray, a + f * (b - a) + n * (i * kStep));
        if (std::isnan(g)) continue;
        profile[static_cast<std::size_t>(i + kHalf)] += g;
        ++count[static_cast<std::size_t>(i + kHalf)];
      }
  }
  // Dark inside and light outside, or (reversed-border families) the other way round.
  const auto mean_at = [&](std::size_t i) { return count[i] ? profile[i] / count[i] : std::nan(""); };
  const double polarity = mean_at(profile.size() - 1) >= mean_at(0) ? 1.0 : -1.0;
  double slope = 0;
  for (std::size_t i = 1; i + 1 < profile.size(); ++i) {
    if (!count[i - 1] || !count[i + 1]) continue;
    slope = std::max(slope, polarity * (mean_at(i + 1) - mean_at(i - 1)) / (2 * kStep));
  }
  // A step of height C blurred by a Gaussian of sigma s has a peak slope C / (s sqrt(2 pi)).
  if (slope <= 0) return std::numeric_limits<double>::infinity();
  return contrast / (slope * std::sqrt(2 * M_PI));
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

std::array<double, 4> edge_phase_lock(const std::array<cv::Point2d, 4>& c, double width_px) {
  std::array<double, 4> lock{};
  for (std::size_t e = 0; e < 4; ++e) {
    const cv::Point2d d = c[(e + 1) % 4] - c[e];
    // Across the grid: the smaller of the two coordinate extents.
    const double drift = std::min(std::abs(d.x), std::abs(d.y));
    lock[e] = std::exp(-(drift / width_px) * (drift / width_px));
  }
  return lock;
}

double mean_edge_length_px(const std::array<cv::Point2d, 4>& c) {
  double sum = 0;
  for (int e = 0; e < 4; ++e) sum += std::hypot(c[(e + 1) % 4].x - c[e].x, c[(e + 1) % 4].y - c[e].y);
  return sum / 4;
}

std::array<double, 4> border_width_px(const std::array<cv::Point2d, 4>& c, int cells_across_border) {
  // The detected square as [-1, 1]^2 in AprilTag's corner order; a cell is 2 / cells wide.
  const cv::Point2f plane[4] = {{-1, 1}, {1, 1}, {1, -1}, {-1, -1}};
  const cv::Point2f image[4] = {c[0], c[1], c[2], c[3]};
  const cv::Matx33d H(cv::getPerspectiveTransform(plane, image));
  const double in = 1 - 2.0 / std::max(cells_across_border, 1);
  std::array<double, 4> width{};
  for (int e = 0; e < 4; ++e) {
    const cv::Point2d a = c[e], b = c[(e + 1) % 4];
    const cv::Vec3d m = H * cv::Vec3d(in * (plane[e].x + plane[(e + 1) % 4].x) / 2,
                                      in * (plane[e].y + plane[(e + 1) % 4].y) / 2, 1);
    const cv::Point2d p(m[0] / m[2], m[1] / m[2]);
    const double length = std::max(std::hypot(b.x - a.x, b.y - a.y), 1e-9);
    width[static_cast<std::size_t>(e)] = std::abs((b - a).cross(p - a)) / length;
  }
  return width;
}

}  // namespace covtrack::fiducial
