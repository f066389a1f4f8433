#include "region_drawing.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fmt/format.h>

namespace covtrack::cli {
namespace {

// Pixel coordinates drawn with 4 fractional bits: sub-pixel placement of thin lines.
constexpr int kShift = 4;
constexpr double kScale = 1 << kShift;

// BGR. Only the inner regions are pure white and only the outer ones pure green, so a
// picture can be checked pixel by pixel; labels are yellow, the legend's text light grey.
const cv::Scalar kBlue(255, 120, 0), kGreen(0, 200, 0), kWhite(255, 255, 255),
    kGrey(160, 160, 160), kRed(0, 0, 255), kYellow(0, 230, 230), kLegend(210, 210, 210),
    kPanel(30, 30, 30);

cv::Point fixed_point(const client::Vec2& p) {
  return {cvRound(p.x() * kScale), cvRound(p.y() * kScale)};
}

void draw_polygon(cv::Mat& image, const client::Polygon& polygon, const cv::Scalar& colour,
                  int thickness = 1) {
  if (polygon.size() < 2) return;
  std::vector<std::vector<cv::Point>> contours(1);
  for (const client::Vec2& p : polygon) contours[0].push_back(fixed_point(p));
  cv::polylines(image, contours, true, colour, thickness, cv::LINE_AA, kShift);
}

}  // namespace

void draw_regions(cv::Mat& image, const RegionsReport& report) {
  const double scale = client::confidence_scale(report.confidence);
  for (const RegionsReport::Object& o : report.objects) {
    const client::ObjectRegions& r = o.regions;
    client::Polygon outline;
    for (int i : r.hull) outline.push_back(r.vertices[i].mean_px);
    draw_polygon(image, outline, kGrey);
    for (const client::ProjectedVertex& v : r.vertices) {
      if (!v.flags.usable()) continue;
      const int sides = client::circumscribed_polygon_sides(
          scale * client::ellipse_axes(v.covariance_px2).major_px, 0.5, 16, 256);
      draw_polygon(image, client::circumscribed_ellipse_polygon(v.mean_px, v.covariance_px2, scale, sides), kBlue);
      cv::circle(image, fixed_point(v.mean_px), 2 * kScale, kGrey, cv::FILLED, cv::LINE_AA, kShift);
    }
    draw_polygon(image, r.outer, kGreen, 2);
    draw_polygon(image, r.inner, kWhite, 2);
    if (r.vertices.empty() || !r.vertices.front().flags.usable()) continue;
    const client::Vec2 at = r.vertices.front().mean_px;
    const std::string label = r.valid ? fmt::format("{} {:.1f} px", o.name, r.assessment)
                                      : fmt::format("{}: no region", o.name);
    cv::putText(image, label, cv::Point(cvRound(at.x()) + 4, cvRound(at.y()) - 4),
                cv::FONT_HERSHEY_SIMPLEX, 0.45, r.valid ? kYellow : kRed, 1, cv::LINE_AA);
  }
}

void draw_legend(cv::Mat& image, const std::vector<std::string>& lines) {
  constexpr int kLine = 16, kMargin = 6;
  int width = 0;
  for (const std::string& line : lines)
    width = std::max(width, cv::getTextSize(line, cv::FONT_HERSHEY_SIMPLEX, 0.4, 1, nullptr).width);
  const cv::Rect panel(0, 0, std::min(image.cols, width + 2 * kMargin),
                       std::min(image.rows, int(lines.size()) * kLine + kMargin));
  image(panel) = kPanel;
  for (std::size_t i = 0; i < lines.size(); ++i)
    cv::putText(image, lines[i], cv::Point(kMargin, kLine * int(i + 1)), cv::FONT_HERSHEY_SIMPLEX,
                0.4, kLegend, 1, cv::LINE_AA);
}

Result<void> write_png(const cv::Mat& image, const std::string& path) {
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
