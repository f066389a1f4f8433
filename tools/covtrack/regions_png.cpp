#include "regions_png.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fmt/format.h>

namespace covtrack::cli {
namespace {

// Pixel coordinates drawn with 4 fractional bits: sub-pixel placement of thin lines.
constexpr int kShift = 4;
constexpr double kScale = 1 << kShift;

std::vector<cv::Point> to_points(const client::Polygon& polygon) {
  std::vector<cv::Point> points;
  for (const client::Vec2& p : polygon) points.emplace_back(cvRound(p.x() * kScale), cvRound(p.y() * kScale));
  return points;
}

void draw_polygon(cv::Mat& image, const client::Polygon& polygon, const cv::Scalar& colour) {
  if (polygon.size() < 2) return;
  const std::vector<std::vector<cv::Point>> contours = {to_points(polygon)};
  cv::polylines(image, contours, true, colour, 1, cv::LINE_AA, kShift);
}

}  // namespace

Result<void> write_regions_png(const RegionsReport& report, const std::string& path) {
  const cv::Scalar background(40, 40, 40), blue(255, 120, 0), green(0, 200, 0),
      white(255, 255, 255), grey(160, 160, 160), red(0, 0, 255);  // BGR
  cv::Mat image(report.camera.height_px, report.camera.width_px, CV_8UC3, background);
  const double scale = client::confidence_scale(report.confidence);
  for (const RegionsReport::Object& o : report.objects) {
    const client::ObjectRegions& r = o.regions;
    for (const client::ProjectedVertex& v : r.vertices) {
      if (!v.flags.usable()) continue;
      const int sides = client::circumscribed_polygon_sides(
          scale * client::ellipse_axes(v.covariance_px2).major_px, 0.5, 16, 256);
      draw_polygon(image, client::circumscribed_ellipse_polygon(v.mean_px, v.covariance_px2, scale, sides), blue);
      cv::circle(image, cv::Point(cvRound(v.mean_px.x() * kScale), cvRound(v.mean_px.y() * kScale)),
                 2 * kScale, grey, cv::FILLED, cv::LINE_AA, kShift);
    }
    draw_polygon(image, r.outer, green);
    draw_polygon(image, r.inner, white);
    if (r.vertices.empty()) continue;
    const client::Vec2 at = r.vertices.front().mean_px;
    const std::string label = r.valid ? fmt::format("{} {:.1f} px", o.name, r.assessment)
                                      : fmt::format("{}: no region", o.name);
    cv::putText(image, label, cv::Point(cvRound(at.x()) + 4, cvRound(at.y()) - 4),
                cv::FONT_HERSHEY_SIMPLEX, 0.45, r.valid ? white : red, 1, cv::LINE_AA);
  }
  bool written = false;
  try {
    written = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    return fail(fmt::format("cannot write {}: {}", path, e.what()));
  }
  if (!written) return fail(fmt::format("cannot write {}", path));
  return {};
}

}  // namespace covtrack::cli
