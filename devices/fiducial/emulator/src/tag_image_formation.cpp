#include "covtrack/emulators/fiducial/tag_image_formation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace covtrack::fiducial {
namespace {

using Polygon = std::vector<cv::Point2d>;

// A convex polygon clipped by axis-aligned half-planes, held without allocating (the
// exact-area rasteriser clips millions of them): a quad clipped four times has at most 8
// vertices, and pixel_coverage's polygons of up to 8 at most 12.
struct SmallPolygon {
  std::array<cv::Point2d, 12> p;
  std::size_t n = 0;
};

// Sutherland-Hodgman against one axis-aligned half-plane: keeps the points whose
// coordinate `axis` (0: x, 1: y) is <= bound (keep_below) or >= bound.
SmallPolygon clip(const SmallPolygon& poly, int axis, double bound, bool keep_below) {
  SmallPolygon out;
  const auto inside = [&](const cv::Point2d& p) {
    const double c = axis == 0 ? p.x : p.y;
    return keep_below ? c <= bound : c >= bound;
  };
  for (std::size_t i = 0; i < poly.n; ++i) {
    const cv::Point2d& a = poly.p[i];
    const cv::Point2d& b = poly.p[(i + 1) % poly.n];
    const bool ia = inside(a), ib = inside(b);
    if (ia) out.p[out.n++] = a;
    if (ia != ib) {
      const double ca = axis == 0 ? a.x : a.y, cb = axis == 0 ? b.x : b.y;
      out.p[out.n++] = a + (b - a) * ((bound - ca) / (cb - ca));
    }
  }
  return out;
}

double area(const SmallPolygon& poly) {
  double s = 0;
  for (std::size_t i = 0; i < poly.n; ++i) s += poly.p[i].cross(poly.p[(i + 1) % poly.n]);
  return std::abs(s) / 2;
}

// The x-range over which the band [y - half, y + half] of a convex polygon covers the
// band's whole height: where its left boundary's larger and its right boundary's smaller
// end lie (both are at the band's top or bottom, the boundaries being convex). Empty when
// the polygon does not reach both.
std::pair<double, double> full_height_span(const SmallPolygon& band, double top, double bottom) {
  constexpr double kOnLinePx = 1e-9;
  double top_lo = 1e18, top_hi = -1e18, bottom_lo = 1e18, bottom_hi = -1e18;
  for (std::size_t i = 0; i < band.n; ++i) {
    const cv::Point2d& q = band.p[i];
    if (std::abs(q.y - top) <= kOnLinePx) top_lo = std::min(top_lo, q.x), top_hi = std::max(top_hi, q.x);
    if (std::abs(q.y - bottom) <= kOnLinePx) bottom_lo = std::min(bottom_lo, q.x), bottom_hi = std::max(bottom_hi, q.x);
  }
  return {std::max(top_lo, bottom_lo), std::min(top_hi, bottom_hi)};
}

// Adds value * (covered fraction of the pixel's light-sensitive square, `aperture` px wide
// about its centre) to every pixel the convex polygon (a quad) touches: rows first (one
// clip per band), then each pixel of the band; a pixel whose square lies where the band is
// covered over its whole height is covered whole, without clipping.
void add_polygon(cv::Mat& image, const Polygon& quad, float value, double aperture) {
  const double half = aperture / 2, per_area = 1 / (aperture * aperture);
  SmallPolygon poly;
  double y_lo = 1e18, y_hi = -1e18;
  for (const auto& q : quad) poly.p[poly.n++] = q, y_lo = std::min(y_lo, q.y), y_hi = std::max(y_hi, q.y);
  const int r0 = std::max(0, static_cast<int>(std::floor(y_lo + 0.5)));
  const int r1 = std::min(image.rows - 1, static_cast<int>(std::floor(y_hi + 0.5)));
  for (int r = r0; r <= r1; ++r) {
    const SmallPolygon band = clip(clip(poly, 1, r - half, false), 1, r + half, true);
    if (band.n < 3) continue;
    double x_lo = 1e18, x_hi = -1e18;
    for (std::size_t i = 0; i < band.n; ++i) x_lo = std::min(x_lo, band.p[i].x), x_hi = std::max(x_hi, band.p[i].x);
    const auto [full_lo, full_hi] = full_height_span(band, r - half, r + half);
    const int c0 = std::max(0, static_cast<int>(std::floor(x_lo + 0.5)));
    const int c1 = std::min(image.cols - 1, static_cast<int>(std::floor(x_hi + 0.5)));
    float* row = image.ptr<float>(r);
    for (int c = c0; c <= c1; ++c) {
      if (c - half >= full_lo && c + half <= full_hi) {
        row[c] += value;
        continue;
      }
      row[c] += value * static_cast<float>(per_area * area(clip(clip(band, 0, c - half, false), 0, c + half, true)));
    }
  }
}

// The tag-plane rectangle [x0, x1] x [y0, y1] (m) in image pixels, through the pinhole.
Polygon project_rect(const Camera& camera, const Pose& T, double x0, double y0, double x1,
                     double y1) {
  Polygon out;
  for (const auto& [x, y] : {std::pair{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}})
    out.push_back(pinhole_pixel(camera, T * Vec3(x, y, 0)));
  return out;
}

// A printed tag on its plane: its cells with the white margin around them, one cell's
// size and half the whole print's width (m).
struct PrintedTag {
  cv::Mat cells;  // CV_8U, >= 128 white
  double cell_m = 0, half_m = 0;
};

// Nothing when the family has no such id or part of the print lies behind the camera.
std::optional<PrintedTag> printed_tag(const TagFamily& family, const RenderedTag& tag, int margin_cells) {
  auto cells = family.cells(tag.id);
  if (!cells) return std::nullopt;
  PrintedTag p;
  cv::copyMakeBorder(*cells, p.cells, margin_cells, margin_cells, margin_cells, margin_cells, cv::BORDER_CONSTANT, 255);
  p.cell_m = tag.size_m / family.cells_across_border();
  p.half_m = p.cell_m * p.cells.cols / 2;
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0})
      if ((tag.T_camera_tag * Vec3(sx * p.half_m, sy * p.half_m, 0)).z() <= 1e-3) return std::nullopt;
  return p;
}

cv::Mat analytic_radiance(const Camera& camera, const TagFamily& family,
                          const std::vector<RenderedTag>& tags, const ImageFormation& f) {
  cv::Mat image(camera.height_px, camera.width_px, CV_32F, cv::Scalar(f.background));
  const double aperture = std::clamp(f.pixel_aperture, 0.05, 1.0);
  for (const RenderedTag& tag : tags) {
    const auto p = printed_tag(family, tag, std::max(0, f.margin_cells));
    if (!p) continue;
    const double h = p->half_m;
    // The paper first, then each row's runs of black cells on it. (Tags must not overlap:
    // coverage is added, not composited.)
    add_polygon(image, project_rect(camera, tag.T_camera_tag, -h, -h, h, h),
                static_cast<float>(f.paper - f.background), aperture);
    for (int r = 0; r < p->cells.rows; ++r) {
      const std::uint8_t* row = p->cells.ptr<std::uint8_t>(r);
      for (int c = 0; c < p->cells.cols;) {
        if (row[c] >= 128) { ++c; continue; }
        int end = c;
        while (end < p->cells.cols && row[end] < 128) ++end;
        const double x0 = -h + c * p->cell_m, x1 = -h + end * p->cell_m, y0 = -h + r * p->cell_m;
        add_polygon(image, project_rect(camera, tag.T_camera_tag, x0, y0, x1, y0 + p->cell_m),
                    static_cast<float>(f.ink - f.paper), aperture);
        c = end;
      }
    }
  }
  return image;
}

// Where the lens puts the pinhole image: each pixel's centre, and its neighbourhood to
// first order (the map is smooth: the second-order term is under 1e-4 px within a pixel).
struct LensMap {
  const cv::Mat* ideal_at = nullptr;  // CV_32FC2: the pinhole point each pixel's centre sees

  // Pixel (c, r)'s neighbourhood: the pinhole point at offset (dx, dy) px from its centre.
  // Read once per pixel, used for every sample in it.
  struct Pixel {
    cv::Point2d centre, du, dv;
    cv::Point2d ideal(double dx, double dy) const { return centre + du * dx + dv * dy; }
  };
  Pixel pixel(int c, int r) const {
    if (!ideal_at) return {cv::Point2d(c, r), cv::Point2d(1, 0), cv::Point2d(0, 1)};
    const auto at = [&](int cc, int rr) {
      const cv::Vec2f v = ideal_at->at<cv::Vec2f>(std::clamp(rr, 0, ideal_at->rows - 1), std::clamp(cc, 0, ideal_at->cols - 1));
      return cv::Point2d(v[0], v[1]);
    };
    return {at(c, r), (at(c + 1, r) - at(c - 1, r)) / 2, (at(c, r + 1) - at(c, r - 1)) / 2};
  }
};

// The box of pixels that may see the polygon (pinhole coordinates) through `lens`: the
// polygon's edges, sampled, where the lens puts them, widened by 2 px. Clamped to the image.
cv::Rect pixels_seeing(const Camera& camera, const cv::Mat& lens, const Polygon& ideal);

cv::Mat jittered_radiance(const Camera& camera, const TagFamily& family,
                          const std::vector<RenderedTag>& tags, const ImageFormation& f,
                          const LensMap& lens = {}) {
  constexpr int kGrid = 16;
  constexpr double kPoints = kGrid * kGrid;
  cv::Mat image(camera.height_px, camera.width_px, CV_32F, cv::Scalar(f.background));
  cv::RNG rng(f.jitter_seed);
  const double aperture = std::clamp(f.pixel_aperture, 0.05, 1.0);
  for (const RenderedTag& tag : tags) {
    const auto p = printed_tag(family, tag, std::max(0, f.margin_cells));
    if (!p) continue;
    const double h = p->half_m;
    const cv::Matx33d to_plane = tag_plane_to_image(camera, tag.T_camera_tag).inv();
    // The print's cell under image point (u, v); (-1, -1) off the print.
    const auto cell_at = [&](double u, double v) {
      const cv::Vec3d q = to_plane * cv::Vec3d(u, v, 1);
      const int col = static_cast<int>(std::floor((q[0] / q[2] + h) / p->cell_m));
      const int row = static_cast<int>(std::floor((q[1] / q[2] + h) / p->cell_m));
      if (col < 0 || row < 0 || col >= p->cells.cols || row >= p->cells.rows) return cv::Point(-1, -1);
      return cv::Point(col, row);
    };
    const auto level = [&](cv::Point cell) { return p->cells.at<std::uint8_t>(cell) >= 128 ? f.paper : f.ink; };
    const Polygon print = project_rect(camera, tag.T_camera_tag, -h, -h, h, h);
    const cv::Rect box = pixels_seeing(camera, lens.ideal_at ? f.true_distortion : cv::Mat(), print);
    const double half = aperture / 2;
    for (int r = box.y; r < box.y + box.height; ++r) {
      float* row = image.ptr<float>(r);
      for (int c = box.x; c < box.x + box.width; ++c) {
        const LensMap::Pixel seen = lens.pixel(c, r);
        const auto cell_seen = [&](double dx, double dy) {
          const cv::Point2d q = seen.ideal(dx, dy);
          return cell_at(q.x, q.y);
        };
        // A sensitive square whose four corners lie in one cell lies in it whole (a
        // homography keeps lines straight, the lens map is affine within a pixel, and the
        // cell is convex): no points needed.
        const cv::Point corner = cell_seen(-half, -half);
        if (corner == cell_seen(half, -half) && corner == cell_seen(-half, half) && corner == cell_seen(half, half)) {
          if (corner.x >= 0) row[c] = static_cast<float>(level(corner));
          continue;
        }
        double sum = 0;
        int on_print = 0;
        for (int i = 0; i < kGrid; ++i)
          for (int j = 0; j < kGrid; ++j) {
            const cv::Point cell = cell_seen(aperture * ((j + rng.uniform(0.0, 1.0)) / kGrid - 0.5),
                                             aperture * ((i + rng.uniform(0.0, 1.0)) / kGrid - 0.5));
            if (cell.x < 0) continue;
            ++on_print;
            sum += level(cell);
          }
        row[c] = static_cast<float>(row[c] * (1 - on_print / kPoints) + sum / kPoints);
      }
    }
  }
  return image;
}

cv::Mat pinhole_radiance(const Camera& camera, const TagFamily& family, const std::vector<RenderedTag>& tags,
                         const ImageFormation& f) {
  if (f.rasteriser == Rasteriser::AnalyticArea) return analytic_radiance(camera, family, tags, f);
  if (f.rasteriser == Rasteriser::JitteredPoints) return jittered_radiance(camera, family, tags, f);
  RenderLook look;
  look.background = f.background, look.black = f.ink, look.white = f.paper;
  look.blur_sigma_px = 0, look.supersample = f.supersample, look.margin_cells = f.margin_cells;
  return render_tags(camera, family, tags, look);
}

// The pinhole point each pixel's centre sees through a lens with `distortion` (CV_32FC2).
// Slow to make (every pixel undistorted iteratively), so kept for the next frame of the
// same camera and lens.
const cv::Mat& lens_map(const Camera& camera, const cv::Mat& distortion) {
  struct Cached { cv::Size size; cv::Matx33d K; cv::Mat distortion, map; };
  thread_local Cached cache;
  const cv::Size size(camera.width_px, camera.height_px);
  const bool same = cache.size == size && cache.K == camera_matrix(camera) &&
                    cache.distortion.size() == distortion.size() &&
                    cv::norm(cache.distortion, distortion, cv::NORM_INF) == 0;
  if (!same) {
    std::vector<cv::Point2f> pixels;
    pixels.reserve(static_cast<std::size_t>(size.area()));
    for (int r = 0; r < size.height; ++r)
      for (int c = 0; c < size.width; ++c) pixels.emplace_back(static_cast<float>(c), static_cast<float>(r));
    std::vector<cv::Point2f> ideal_at;
    cv::undistortPoints(pixels, ideal_at, camera_matrix(camera), distortion, cv::noArray(), camera_matrix(camera));
    cache = {size, camera_matrix(camera), distortion.clone(), cv::Mat(size, CV_32FC2, ideal_at.data()).clone()};
  }
  return cache.map;
}

cv::Rect pixels_seeing(const Camera& camera, const cv::Mat& lens, const Polygon& ideal) {
  constexpr int kPerEdge = 16;
  std::vector<cv::Point2d> image;
  for (std::size_t e = 0; e < ideal.size(); ++e)
    for (int j = 0; j < kPerEdge; ++j)
      image.push_back(ideal[e] + (ideal[(e + 1) % ideal.size()] - ideal[e]) * (static_cast<double>(j) / kPerEdge));
  if (!lens.empty()) {
    std::vector<cv::Point3d> rays;
    for (const auto& q : image) rays.emplace_back((q.x - camera.cx) / camera.fx, (q.y - camera.cy) / camera.fy, 1);
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix(camera), lens, image);
  }
  double u0 = 1e18, v0 = 1e18, u1 = -1e18, v1 = -1e18;
  for (const auto& q : image)
    u0 = std::min(u0, q.x), v0 = std::min(v0, q.y), u1 = std::max(u1, q.x), v1 = std::max(v1, q.y);
  if (!(u0 <= u1 && v0 <= v1) || u1 < -1e6 || v1 < -1e6 || u0 > 1e6 || v0 > 1e6) return {};
  const int c0 = static_cast<int>(std::floor(u0)) - 2, r0 = static_cast<int>(std::floor(v0)) - 2;
  const int c1 = static_cast<int>(std::ceil(u1)) + 2, r1 = static_cast<int>(std::ceil(v1)) + 2;
  return cv::Rect(c0, r0, c1 - c0 + 1, r1 - r0 + 1) & cv::Rect(0, 0, camera.width_px, camera.height_px);
}

// The supersampling and exact-area rasterisers through a lens: each pixel the mean of the
// pinhole radiance over its footprint (its sensitive square), from a pinhole rendering
// kFine times finer of the region the print covers, resampled through the lens there and
// averaged over each pixel's kFine x kFine sub-samples. Resampling
// a pinhole image at the pixels' own scale instead blurs each edge by the sub-pixel phase
// of its place, varying along every edge as no camera's optics do: the corner model took
// that for error of a distorted camera (NEES 6.5 on one against 5.5 on a pinhole one).
cv::Mat fine_lens_radiance(const Camera& camera, const TagFamily& family, const std::vector<RenderedTag>& tags,
                           const ImageFormation& f) {
  constexpr int kFine = 4;
  const LensMap lens{&lens_map(camera, f.true_distortion)};
  // The exact area integrates the sensitive square only (as without a lens); the
  // supersampling, the whole pixel.
  const double aperture = f.rasteriser == Rasteriser::AnalyticArea ? std::clamp(f.pixel_aperture, 0.05, 1.0) : 1.0;
  cv::Mat image(camera.height_px, camera.width_px, CV_32F, cv::Scalar(f.background));
  ImageFormation pinhole = f;
  pinhole.supersample = 1;     // the area averaging below is the supersampling
  pinhole.pixel_aperture = 1;  // and the fine pixels' sensitive square, the whole fine pixel
  // Each tag's pixels (empty when it is not drawn): a box is rendered from the tags that
  // reach it only, not from every tag of the frame.
  std::vector<cv::Rect> boxes;
  for (const RenderedTag& tag : tags) {
    const auto p = printed_tag(family, tag, std::max(0, f.margin_cells));
    boxes.push_back(p ? pixels_seeing(camera, f.true_distortion,
                                      project_rect(camera, tag.T_camera_tag, -p->half_m, -p->half_m, p->half_m, p->half_m))
                      : cv::Rect());
  }
  std::vector<RenderedTag> reaching;
  for (const cv::Rect& box : boxes) {
    if (box.empty()) continue;
    reaching.clear();
    for (std::size_t j = 0; j < tags.size(); ++j)
      if (!(boxes[j] & box).empty()) reaching.push_back(tags[j]);
    // Each sub-sample's pinhole point, kFine x kFine over each pixel's sensitive square, in
    // fine pixels (x_fine = kFine x + (kFine - 1) / 2).
    cv::Mat fine_at(box.size() * kFine, CV_32FC2);
    for (int r = 0; r < box.height; ++r)
      for (int c = 0; c < box.width; ++c) {
        const LensMap::Pixel seen = lens.pixel(box.x + c, box.y + r);
        for (int i = 0; i < kFine; ++i)
          for (int j = 0; j < kFine; ++j) {
            const cv::Point2d q = seen.ideal(aperture * ((j + 0.5) / kFine - 0.5), aperture * ((i + 0.5) / kFine - 0.5));
            fine_at.at<cv::Vec2f>(r * kFine + i, c * kFine + j) =
                cv::Vec2f(static_cast<float>(kFine * q.x + (kFine - 1) / 2.0), static_cast<float>(kFine * q.y + (kFine - 1) / 2.0));
          }
      }
    std::vector<cv::Mat> xy;
    cv::split(fine_at, xy);
    double x_lo, x_hi, y_lo, y_hi;
    cv::minMaxLoc(xy[0], &x_lo, &x_hi);
    cv::minMaxLoc(xy[1], &y_lo, &y_hi);
    const int x0 = static_cast<int>(std::floor(x_lo)) - 2, y0 = static_cast<int>(std::floor(y_lo)) - 2;
    Camera fine = camera;
    fine.fx *= kFine, fine.fy *= kFine;
    fine.cx = kFine * camera.cx + (kFine - 1) / 2.0 - x0, fine.cy = kFine * camera.cy + (kFine - 1) / 2.0 - y0;
    fine.width_px = static_cast<int>(std::ceil(x_hi)) + 3 - x0, fine.height_px = static_cast<int>(std::ceil(y_hi)) + 3 - y0;
    fine_at -= cv::Scalar(x0, y0);
    cv::Mat seen, averaged;
    cv::remap(pinhole_radiance(fine, family, reaching, pinhole), seen, fine_at, cv::noArray(), cv::INTER_LINEAR,
              cv::BORDER_REPLICATE);
    cv::resize(seen, averaged, box.size(), 0, 0, cv::INTER_AREA);
    averaged.copyTo(image(box));
  }
  return image;
}

// The radiance a lens with f.true_distortion forms of the tags.
cv::Mat lens_radiance(const Camera& camera, const TagFamily& family, const std::vector<RenderedTag>& tags,
                      const ImageFormation& f) {
  if (f.rasteriser == Rasteriser::JitteredPoints)
    return jittered_radiance(camera, family, tags, f, LensMap{&lens_map(camera, f.true_distortion)});
  return fine_lens_radiance(camera, family, tags, f);
}

// A disk of `radius` px, each tap weighted by its covered area (8 x 8 sub-samples).
cv::Mat disk_kernel(double radius) {
  const int half = static_cast<int>(std::ceil(radius));
  cv::Mat k(2 * half + 1, 2 * half + 1, CV_32F, cv::Scalar(0));
  constexpr int kSub = 8;
  for (int r = -half; r <= half; ++r)
    for (int c = -half; c <= half; ++c) {
      int in = 0;
      for (int i = 0; i < kSub; ++i)
        for (int j = 0; j < kSub; ++j) {
          const double x = c - 0.5 + (j + 0.5) / kSub, y = r - 0.5 + (i + 0.5) / kSub;
          in += x * x + y * y <= radius * radius;
        }
      k.at<float>(r + half, c + half) = static_cast<float>(in);
    }
  return k / cv::sum(k)[0];
}

}  // namespace

double pixel_coverage(const std::vector<cv::Point2d>& polygon, int x, int y) {
  // Four clips add at most four vertices: 8 + 4 fit SmallPolygon.
  if (polygon.size() > 8) return std::numeric_limits<double>::quiet_NaN();
  SmallPolygon poly;
  for (const auto& q : polygon) poly.p[poly.n++] = q;
  return area(clip(clip(clip(clip(poly, 1, y - 0.5, false), 1, y + 0.5, true), 0, x - 0.5, false),
                   0, x + 0.5, true));
}

cv::Mat tag_radiance(const Camera& camera, const TagFamily& family,
                     const std::vector<RenderedTag>& tags, const ImageFormation& f) {
  if (!f.true_distortion.empty() && cv::countNonZero(f.true_distortion) > 0)
    return lens_radiance(camera, family, tags, f);
  return pinhole_radiance(camera, family, tags, f);
}

cv::Mat form_image(const Camera& camera, const TagFamily& family,
                   const std::vector<RenderedTag>& tags, const ImageFormation& f,
                   std::mt19937_64& rng) {
  cv::Mat linear = tag_radiance(camera, family, tags, f) * f.exposure;
  if (f.gauss_blur_px > 0) cv::GaussianBlur(linear, linear, {0, 0}, f.gauss_blur_px, 0, cv::BORDER_REPLICATE);
  if (f.defocus_radius_px > 0)
    cv::filter2D(linear, linear, -1, disk_kernel(f.defocus_radius_px), {-1, -1}, 0, cv::BORDER_REPLICATE);

  if (f.vignetting != 0) {
    const double half_diagonal2 =
        (camera.width_px * camera.width_px + camera.height_px * camera.height_px) / 4.0;
    for (int r = 0; r < linear.rows; ++r) {
      float* row = linear.ptr<float>(r);
      const double dy2 = (r - camera.cy) * (r - camera.cy);
      for (int c = 0; c < linear.cols; ++c)
        row[c] *= static_cast<float>(1 - f.vignetting * ((c - camera.cx) * (c - camera.cx) + dy2) / half_diagonal2);
    }
  }
  // Shot noise (variance proportional to the signal) and read noise, in linear light.
  cv::Mat sd(linear.size(), CV_32F, cv::Scalar((f.read_noise / 255) * (f.read_noise / 255)));
  if (f.full_well_e > 0) sd += cv::max(linear, 0) / f.full_well_e;
  cv::sqrt(sd, sd);
  cv::Mat noise(linear.size(), CV_32F);
  cv::RNG cv_rng(rng());
  cv_rng.fill(noise, cv::RNG::NORMAL, 0, 1);
  linear += noise.mul(sd);
  // The tone curve, then 8 bits.
  linear = cv::min(cv::max(linear, 0), 1);
  if (f.gamma != 1) cv::pow(linear, 1 / std::max(f.gamma, 1e-3), linear);
  cv::Mat out;
  linear.convertTo(out, CV_8U, 255);
  if (f.jpeg_quality > 0) {
    std::vector<std::uint8_t> bytes;
    cv::imencode(".jpg", out, bytes, {cv::IMWRITE_JPEG_QUALITY, f.jpeg_quality});
    out = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  }
  return out;
}

}  // namespace covtrack::fiducial
