#include "region_drawing.hpp"

#include <algorithm>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fmt/format.h>

#include "view_labels.hpp"

namespace covtrack::cli {
namespace {

// Pixel coordinates drawn with 4 fractional bits: sub-pixel placement of thin lines.
constexpr int kShift = 4;
constexpr double kScale = 1 << kShift;

// BGR. Only the inner regions are pure white and only the outer ones pure green, so a
// picture can be checked pixel by pixel; labels are yellow, the legend's text light grey.
const cv::Scalar kBlue(255, 120, 0), kGreen(0, 200, 0), kWhite(255, 255, 255),
    kGrey(160, 160, 160), kRed(0, 0, 255), kYellow(0, 230, 230), kLegend(210, 210, 210),
    kPanel(30, 30, 30), kCyan(230, 200, 0), kMagenta(230, 0, 230), kOrange(0, 150, 255);

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

cv::Scalar likelihood_colour(double likelihood) {
  const double p = std::clamp(likelihood, 0.0, 1.0);
  return cv::Scalar(0, 255 * (1 - p), 255);
}

namespace {

// Translucent fills go under every line, so outlines keep their pure colours.
void fill_polygon(cv::Mat& image, const client::Polygon& polygon, const cv::Scalar& colour, double alpha) {
  if (polygon.size() < 3) return;
  std::vector<cv::Point> points;
  for (const client::Vec2& p : polygon) {
    if (!p.allFinite()) return;
    points.push_back(fixed_point(p));
  }
  // Blend only the polygon's bounding box: a whole-frame copy per object costs more.
  cv::Rect bounds = cv::boundingRect(points);
  bounds = cv::Rect(bounds.x >> kShift, bounds.y >> kShift, (bounds.width >> kShift) + 2, (bounds.height >> kShift) + 2) &
           cv::Rect(0, 0, image.cols, image.rows);
  if (bounds.empty()) return;
  for (cv::Point& p : points) p -= cv::Point(bounds.x << kShift, bounds.y << kShift);
  cv::Mat roi = image(bounds);
  cv::Mat layer = roi.clone();
  cv::fillConvexPoly(layer, points, colour, cv::LINE_AA, kShift);
  cv::addWeighted(layer, alpha, roi, 1 - alpha, 0, roi);
}

client::Polygon outline_of(const client::ObjectRegions& r) {
  client::Polygon outline;
  for (int i : r.hull) outline.push_back(r.vertices[i].mean_px);
  return outline;
}

void draw_vertex_ellipses(cv::Mat& image, const client::ObjectRegions& r, double scale) {
  for (const client::ProjectedVertex& v : r.vertices) {
    if (!v.flags.usable()) continue;
    const int sides = client::circumscribed_polygon_sides(
        scale * client::ellipse_axes(v.covariance_px2).major_px, 0.5, 16, 256);
    draw_polygon(image, client::circumscribed_ellipse_polygon(v.mean_px, v.covariance_px2, scale, sides), kBlue);
    cv::circle(image, fixed_point(v.mean_px), 2 * kScale, kGrey, cv::FILLED, cv::LINE_AA, kShift);
  }
}

void draw_box(cv::Mat& image, const client::Box& b, const std::string& text, const cv::Scalar& colour) {
  const cv::Rect box(cvRound(b.min.x()), cvRound(b.min.y()), cvRound(b.width()), cvRound(b.height()));
  cv::rectangle(image, box, kPanel, cv::FILLED);
  cv::putText(image, text, cv::Point(box.x + kLabelPad, box.y + box.height - kLabelPad - 3), kLabelFont, kLabelFontScale,
              colour, 1, cv::LINE_AA);
}

void draw_pointer(cv::Mat& image, const WidgetFrame& w) {
  const client::Pointer& pointer = *w.pointer;
  if (pointer.lost) return;
  draw_polygon(image, pointer.region, kMagenta, 1);
  const cv::Point tip = fixed_point(pointer.position_px);
  const int arm = 6 * kScale;
  cv::line(image, tip - cv::Point(arm, 0), tip + cv::Point(arm, 0), kMagenta, 1, cv::LINE_AA, kShift);
  cv::line(image, tip - cv::Point(0, arm), tip + cv::Point(0, arm), kMagenta, 1, cv::LINE_AA, kShift);
}

}  // namespace

void draw_regions(cv::Mat& image, const RegionsReport& report, const WidgetFrame* widgets, int reserved_bottom_px) {
  const double scale = client::confidence_scale(report.confidence);
  const auto augmentation = [&](std::size_t i) {
    return widgets ? widgets->augmentations[i] : scene::Augmentation::outline;
  };
  const bool selecting = widgets && widgets->pointer;
  for (std::size_t i = 0; i < report.objects.size(); ++i) {
    const client::ObjectRegions& r = report.objects[i].regions;
    // As the dissertation's figure 19: the outer regions filled by likelihood; otherwise
    // the Level-of-Error "region" augmentation shades where the object can be.
    if (selecting) fill_polygon(image, r.outer, likelihood_colour(widgets->likelihoods[i]), 0.35);
    else if (augmentation(i) == scene::Augmentation::region) fill_polygon(image, r.outer, kCyan, 0.3);
  }

  for (std::size_t i = 0; i < report.objects.size(); ++i) {
    const client::ObjectRegions& r = report.objects[i].regions;
    const bool selected = selecting && widgets->selection.selected == static_cast<int>(i);
    const bool clicked = widgets && widgets->clicked == static_cast<int>(i);
    const bool bold = widgets && augmentation(i) == scene::Augmentation::outline;
    draw_polygon(image, outline_of(r), clicked ? kOrange : selected ? kRed : bold ? kCyan : kGrey,
                 clicked ? 3 : selected || bold ? 2 : 1);
    draw_vertex_ellipses(image, r, scale);
    draw_polygon(image, r.outer, kGreen, 2);
    draw_polygon(image, r.inner, kWhite, 2);
  }
  if (selecting) draw_pointer(image, *widgets);

  const ViewLabels labels = layout_labels(report, widgets, cv::Size(image.cols, image.rows - reserved_bottom_px));
  for (std::size_t i = 0; i < labels.placed.size(); ++i) {
    const client::PlacedLabel& p = labels.placed[i];
    if (p.leader)
      cv::line(image, fixed_point((*p.leader)[0]), fixed_point((*p.leader)[1]), kYellow, 1, cv::LINE_AA, kShift);
    draw_box(image, p.box, labels.texts[i], report.objects[i].regions.valid ? kYellow : kRed);
  }
  // Indirect selection: one target per candidate, spaced by the pointer's error.
  if (widgets)
    for (const client::SelectionTarget& t : widgets->targets) {
      draw_box(image, t.box, report.objects[static_cast<std::size_t>(t.object)].name, kMagenta);
      const cv::Rect r(cvRound(t.box.min.x()), cvRound(t.box.min.y()), cvRound(t.box.width()), cvRound(t.box.height()));
      cv::rectangle(image, r, kMagenta, 1);
    }
}

constexpr int kLegendLine = 16, kLegendMargin = 6;

int legend_height_px(std::size_t line_count, int rows) {
  return std::min(rows, int(line_count) * kLegendLine + kLegendMargin);
}

void draw_legend(cv::Mat& image, const std::vector<std::string>& lines) {
  // Bottom-left: the label placer lists unanchored labels in the top-left corner.
  int width = 0;
  for (const std::string& line : lines)
    width = std::max(width, cv::getTextSize(line, kLabelFont, 0.4, 1, nullptr).width);
  const int height = legend_height_px(lines.size(), image.rows);
  const cv::Rect panel(0, image.rows - height, std::min(image.cols, width + 2 * kLegendMargin), height);
  image(panel) = kPanel;
  for (std::size_t i = 0; i < lines.size(); ++i)
    cv::putText(image, lines[i], cv::Point(kLegendMargin, panel.y + kLegendLine * int(i + 1) - 2), kLabelFont, 0.4, kLegend, 1,
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
