#pragma once
// `covtrack view --video FILE`: a video that browsers play, chosen by FILE's ending:
// .mp4 holds H.264 (FFmpeg's libx264), .webm holds VP9 (libvpx), both written through
// OpenCV's FFmpeg backend in 4:2:0, which is what browsers decode.
#include <optional>
#include <string>

#include <opencv2/videoio.hpp>

#include "covtrack/protocol/result.hpp"

namespace covtrack::cli {

struct VideoFormat {
  int fourcc;
  std::string codec;        // "H.264", "VP9"
  std::string alternative;  // the other ending, for when this encoder is missing
};

// By the file name's ending; an error saying which endings work for any other.
Result<VideoFormat> video_format_for(const std::string& path);

// The writer, or an error naming the file, the codec and the alternative.
Result<cv::VideoWriter> open_video(const std::string& path, const VideoFormat& format, double fps, cv::Size size);

}  // namespace covtrack::cli
