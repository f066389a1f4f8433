#pragma once
// A picture a command drew, against a reviewed one in tests/tools/golden/. With
// COVTRACK_UPDATE_GOLDEN set in the environment, the new picture becomes the reviewed one
// (to accept a deliberate change; review it before committing).
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

namespace covtrack::testing {

// The fraction of pixels in which some channel differs by more than 48 levels (of 255):
// anti-aliasing and rasterisation leave a few such pixels, a moved line or label many.
// None when either picture cannot be read or their sizes differ.
inline std::optional<double> golden_difference(const std::string& png, const std::string& golden) {
  if (std::getenv("COVTRACK_UPDATE_GOLDEN"))
    std::filesystem::copy_file(png, golden, std::filesystem::copy_options::overwrite_existing);
  const cv::Mat image = cv::imread(png, cv::IMREAD_COLOR), expected = cv::imread(golden, cv::IMREAD_COLOR);
  if (image.empty() || expected.empty() || image.size() != expected.size()) return std::nullopt;
  cv::Mat difference;
  cv::absdiff(image, expected, difference);
  int differing = 0;
  for (int y = 0; y < difference.rows; ++y)
    for (int x = 0; x < difference.cols; ++x) {
      const cv::Vec3b d = difference.at<cv::Vec3b>(y, x);
      differing += std::max({d[0], d[1], d[2]}) > 48;
    }
  return double(differing) / (image.rows * image.cols);
}

}  // namespace covtrack::testing
