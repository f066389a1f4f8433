#pragma once
// Drawing a RegionsReport over an image, in the dissertation's colours: error ellipses
// blue, outer regions green, inner regions white; the object's outline (the hull of its
// projected vertices) grey; labels (yellow) placed by the label placer; a legend in the
// bottom-left corner. Used by `covtrack regions --png` and
// `covtrack view`. With the view's widgets: each object's Level-of-Error augmentation
// (outline: its outline bold cyan; region: its outer region shaded cyan; label: its
// label listed, not anchored); with a pointer, the outer regions filled by selection
// likelihood from yellow (0) to red (1) (as in the dissertation's figure 19) instead of the
// cyan shade, the selected object outlined red, the pointer's region magenta, and the
// indirect targets when the selection is ambiguous.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "covtrack/protocol/result.hpp"
#include "regions_report.hpp"
#include "view_widgets.hpp"

namespace covtrack::cli {

// `image` must be 8-bit BGR; drawn on in place. Labels keep out of the bottom
// `reserved_bottom_px` rows (where the legend goes).
void draw_regions(cv::Mat& image, const RegionsReport& report, const WidgetFrame* widgets = nullptr,
                  int reserved_bottom_px = 0);

// The selection likelihood's colour (BGR): yellow at 0 to red at 1.
cv::Scalar likelihood_colour(double likelihood);
void draw_legend(cv::Mat& image, const std::vector<std::string>& lines);
// The rows draw_legend covers at the bottom of an image `rows` high.
int legend_height_px(std::size_t line_count, int rows);

Result<void> write_png(const cv::Mat& image, const std::string& path);

}  // namespace covtrack::cli
