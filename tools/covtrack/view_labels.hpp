#pragma once
// Each object's label in a frame: its text (name and assessment; short, so that it fits
// inside more often: the likelihood is the fill's colour) and where the label placer
// (label_placer.hpp) puts it: inside the inner region when it fits, else outside the outer
// region with a leader line, else in the list in the top-left corner. The Level-of-Error
// "label" augmentation does not rely on registration, so its label is always listed.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "covtrack/client/label_placer.hpp"
#include "covtrack/client/regions.hpp"
#include "regions_report.hpp"
#include "view_widgets.hpp"

namespace covtrack::cli {

struct ViewLabels {
  std::vector<std::string> texts;             // one per object
  std::vector<client::PlacedLabel> placed;    // one per object
};

// An object's label: its name and assessment, or that it has no region.
std::string label_text(const std::string& name, const client::ObjectRegions& regions);

// widgets may be null (`covtrack regions --png`: no widgets).
ViewLabels layout_labels(const RegionsReport& report, const WidgetFrame* widgets, const cv::Size& screen);

// The labels' font, shared by layout and drawing so that boxes fit their text.
inline constexpr int kLabelFont = 0;  // cv::FONT_HERSHEY_SIMPLEX
inline constexpr double kLabelFontScale = 0.45;
inline constexpr int kLabelPad = 2;

// The box (px) a label with this text needs: the text plus kLabelPad on every side.
client::Vec2 label_box_px(const std::string& text);

}  // namespace covtrack::cli
