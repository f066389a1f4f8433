#include "region_drawing.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fmt/format.h>

#include "covtrack/client/label_placer.hpp"

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

const int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.45;
constexpr int kLabelPad = 2;

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
  std::vector<client::LabelRequest> labels;
  std::vector<std::string> texts;
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
    texts.push_back(r.valid ? fmt::format("{} {:.1f} px", o.name, r.assessment) : fmt::format("{}: no region", o.name));
    int baseline = 0;
    const cv::Size text = cv::getTextSize(texts.back(), kFont, kFontScale, 1, &baseline);
    labels.push_back({r.inner, r.outer, client::Vec2(text.width + 2 * kLabelPad, text.height + baseline + 2 * kLabelPad)});
  }
  // Labels by the seed's placer (5.6.3): inside the inner region when they fit, else
  // outside the outer region with a leader line, else listed in the top-left corner.
  client::LabelPlacerOptions options;
  options.screen = {client::Vec2(0, 0), client::Vec2(image.cols, image.rows)};
  const std::vector<client::PlacedLabel> placed = client::place_labels(labels, options);
  for (std::size_t i = 0; i < placed.size(); ++i) {
    const client::PlacedLabel& p = placed[i];
    const bool valid = report.objects[i].regions.valid;
    if (p.leader)
      cv::line(image, fixed_point((*p.leader)[0]), fixed_point((*p.leader)[1]), kYellow, 1, cv::LINE_AA, kShift);
    const cv::Rect box(cvRound(p.box.min.x()), cvRound(p.box.min.y()), cvRound(p.box.width()), cvRound(p.box.height()));
    cv::rectangle(image, box, kPanel, cv::FILLED);
    cv::putText(image, texts[i], cv::Point(box.x + kLabelPad, box.y + box.height - kLabelPad - 3), kFont,
                kFontScale, valid ? kYellow : kRed, 1, cv::LINE_AA);
  }
}

void draw_legend(cv::Mat& image, const std::vector<std::string>& lines) {
  // Bottom-left: the label placer lists unanchored labels in the top-left corner.
  constexpr int kLine = 16, kMargin = 6;
  int width = 0;
  for (const std::string& line : lines)
    width = std::max(width, cv::getTextSize(line, kFont, 0.4, 1, nullptr).width);
  const int height = std::min(image.rows, int(lines.size()) * kLine + kMargin);
  const cv::Rect panel(0, image.rows - height, std::min(image.cols, width + 2 * kMargin), height);
  image(panel) = kPanel;
  for (std::size_t i = 0; i < lines.size(); ++i)
    cv::putText(image, lines[i], cv::Point(kMargin, panel.y + kLine * int(i + 1) - 2), kFont, 0.4, kLegend, 1,
                cv::LINE_AA);
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
