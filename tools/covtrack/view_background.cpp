#include "view_background.hpp"

#include <filesystem>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fmt/format.h>

namespace covtrack::cli {
namespace {

std::optional<cv::Scalar> parse_colour(const std::string& spec) {
  unsigned r = 0, g = 0, b = 0;
  if (spec.size() == 7 && spec[0] == '#' && std::sscanf(spec.c_str() + 1, "%2x%2x%2x", &r, &g, &b) == 3)
    return cv::Scalar(b, g, r);
  return std::nullopt;
}

}  // namespace

cv::Mat fit_to_view(const cv::Mat& frame, cv::Size size) {
  cv::Mat out;
  if (frame.size() == size) {
    out = frame.clone();
  } else {
    cv::resize(frame, out, size);
  }
  if (out.channels() == 1) cv::cvtColor(out, out, cv::COLOR_GRAY2BGR);
  return out;
}

ViewBackground::ViewBackground(const std::string& spec, cv::Size size, std::string& warning)
    : size_(size), name_(spec) {
  // OpenCV logs its backends' failures itself; ours say the same once, with the fix.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  if (spec.empty()) return;
  if (const auto colour = parse_colour(spec)) {
    colour_ = *colour;
    return;
  }
  try {
    if (spec.starts_with("camera:")) {
      is_camera_ = true;
      video_.emplace(std::stoi(spec.substr(7)));
    } else if (!std::filesystem::exists(spec)) {
      warning = fmt::format("background {}: no such file; drawing on a plain background", spec);
      return;
    } else if (cv::Mat image = cv::imread(spec, cv::IMREAD_COLOR); !image.empty()) {
      still_ = fit_to_view(image, size_);
      return;
    } else {
      video_.emplace(spec, cv::CAP_FFMPEG);  // not every backend in turn, each complaining
    }
  } catch (const std::exception& e) {  // std::stoi, or OpenCV refusing the source
    warning = fmt::format("background {}: {}", spec, e.what());
    video_.reset();
  }
  if (video_ && !video_->isOpened()) {
    warning = fmt::format("background {}: cannot open it as {}", spec,
                          is_camera_ ? "a camera (is it plugged in and not in use?)" : "an image or a video");
    video_.reset();
  }
  // A camera asked for and not there makes the view pointless; a file is only scenery.
  if (!video_) {
    camera_unavailable_ = is_camera_;
    if (!is_camera_) warning += "; drawing on a plain background";
  }
}

cv::Mat ViewBackground::next(std::string& warning) {
  if (video_) {
    cv::Mat frame;
    try {
      if (!video_->read(frame) && !is_camera_) {  // a file's end: loop
        video_->set(cv::CAP_PROP_POS_FRAMES, 0);
        video_->read(frame);
      }
    } catch (const cv::Exception& e) {
      frame.release();
    }
    if (!frame.empty()) return fit_to_view(frame, size_);
    warning = fmt::format("background {}: no more frames (corrupt or unplugged); drawing on a plain background",
                          name_);
    video_.reset();
  }
  if (!still_.empty()) return still_.clone();
  return cv::Mat(size_, CV_8UC3, colour_);
}

}  // namespace covtrack::cli
