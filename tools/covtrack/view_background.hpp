#pragma once
// What `covtrack view` draws on: a plain colour, an image, a video file (looped) or a
// camera (the video see-through case). A file that cannot be opened, or a
// source that stops delivering, is reported once and replaced by the plain colour: the
// view goes on. A camera that cannot be opened at the start ends the view.
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
  // camera:N was asked for and could not be opened (`warning` says so): the view ends.
  bool camera_unavailable() const { return camera_unavailable_; }

 private:
  cv::Size size_;
  cv::Scalar colour_{40, 40, 40};
  cv::Mat still_;
  std::optional<cv::VideoCapture> video_;
  bool is_camera_ = false;
  bool camera_unavailable_ = false;
  std::string name_;
};

}  // namespace covtrack::cli
