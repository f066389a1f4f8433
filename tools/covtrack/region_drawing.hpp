#pragma once
// Drawing a RegionsReport over an image, in the seed's colours: error ellipses blue, outer
// regions green, inner regions white; the object's outline (the hull of its projected
// vertices) grey; labels (yellow) placed by the seed's label placer; a legend in the
// bottom-left corner. Used by `covtrack regions --png` and
// `covtrack view`.
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "covtrack/protocol/result.hpp"
#include "regions_report.hpp"

namespace covtrack::cli {

// `image` must be 8-bit BGR; drawn on in place.
void draw_regions(cv::Mat& image, const RegionsReport& report);
void draw_legend(cv::Mat& image, const std::vector<std::string>& lines);

Result<void> write_png(const cv::Mat& image, const std::string& path);

}  // namespace covtrack::cli
