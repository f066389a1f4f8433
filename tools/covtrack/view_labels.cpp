#include "view_labels.hpp"

#include <opencv2/imgproc.hpp>

#include <fmt/format.h>

namespace covtrack::cli {

client::Vec2 label_box_px(const std::string& text) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kLabelFont, kLabelFontScale, 1, &baseline);
  return {size.width + 2 * kLabelPad, size.height + baseline + 2 * kLabelPad};
}

std::string label_text(const std::string& name, const client::ObjectRegions& r) {
  return r.valid ? fmt::format("{} {:.1f}px", name, r.assessment) : fmt::format("{}: no region", name);
}

ViewLabels layout_labels(const RegionsReport& report, const WidgetFrame* widgets, const cv::Size& screen) {
  ViewLabels out;
  std::vector<client::LabelRequest> requests;
  for (std::size_t i = 0; i < report.objects.size(); ++i) {
    const RegionsReport::Object& o = report.objects[i];
    const client::ObjectRegions& r = o.regions;
    std::string text = label_text(o.name, r);
    const client::Vec2 box = label_box_px(text);
    const bool listed = widgets && widgets->augmentations[i] == scene::Augmentation::label;
    requests.push_back(listed ? client::LabelRequest{{}, {}, box} : client::LabelRequest{r.inner, r.outer, box});
    out.texts.push_back(std::move(text));
  }
  client::LabelPlacerOptions options;
  options.screen = {client::Vec2(0, 0), client::Vec2(screen.width, screen.height)};
  out.placed = client::place_labels(requests, options);
  return out;
}

}  // namespace covtrack::cli
