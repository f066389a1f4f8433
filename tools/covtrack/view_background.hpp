#pragma once
// What `covtrack view` draws on: a plain colour, an image, a video file (looped) or a
// camera (the video see-through case of seed 4.6.1). A source that cannot be opened or
// stops delivering is reported once and replaced by the plain colour: the view goes on.
#include <optional>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

namespace covtrack::cli {

// `frame` at the view's size, 8-bit BGR: a copy the caller may draw on.
cv::Mat fit_to_view(const cv::Mat& frame, cv::Size size);

class ViewBackground {
 public:
  // spec: "#rrggbb", "camera:N", or an image or video file. Problems go to `warning`.
  ViewBackground(const std::string& spec, cv::Size size, std::string& warning);
  // The next frame at the view's size (a copy the caller may draw on). Sets `warning`
  // when the source fails now.
  cv::Mat next(std::string& warning);

 private:
  cv::Size size_;
  cv::Scalar colour_{40, 40, 40};
  cv::Mat still_;
  std::optional<cv::VideoCapture> video_;
  bool is_camera_ = false;
  std::string name_;
};

}  // namespace covtrack::cli
