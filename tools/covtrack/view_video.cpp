#include "view_video.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include <fmt/format.h>

namespace covtrack::cli {

Result<VideoFormat> video_format_for(const std::string& path) {
  const std::string ending = std::filesystem::path(path).extension().string();
  if (ending == ".mp4") return VideoFormat{cv::VideoWriter::fourcc('a', 'v', 'c', '1'), "H.264", ".webm (VP9)"};
  if (ending == ".webm") return VideoFormat{cv::VideoWriter::fourcc('V', 'P', '9', '0'), "VP9", ".mp4 (H.264)"};
  return fail(fmt::format("--video {}: name it .mp4 (H.264) or .webm (VP9), formats browsers play", path));
}

Result<cv::VideoWriter> open_video(const std::string& path, const VideoFormat& format, double fps, cv::Size size) {
  // Only FFmpeg: another backend would take the name and write something browsers refuse.
  // OpenCV prints "tag 'VP90' is not supported ... fallback" to stderr for every .webm
  // (the WebM muxer names codecs, not tags) and writes VP9 all the same: kept off the terminal.
  std::fflush(stderr);
  const int saved_stderr = ::dup(STDERR_FILENO);
  if (const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC); null >= 0) {
    ::dup2(null, STDERR_FILENO);
    ::close(null);
  }
  cv::VideoWriter writer(path, cv::CAP_FFMPEG, format.fourcc, fps, size);
  if (saved_stderr >= 0) {
    ::dup2(saved_stderr, STDERR_FILENO);
    ::close(saved_stderr);
  }
  if (writer.isOpened()) return writer;
  return fail(fmt::format("cannot write {} as {}: its folder is not writable, or OpenCV's FFmpeg here has no {} "
                          "encoder (then name the file {})",
                          path, format.codec, format.codec, format.alternative));
}

}  // namespace covtrack::cli
