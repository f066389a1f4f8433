#include "frame_source.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "covtrack/devices/file_kind.hpp"
#include "image_sequence.hpp"

namespace covtrack::fiducial {
namespace {

std::string camera_node(const std::string& index) { return "/dev/video" + index; }

// The camera's node must be a character device before V4L2 opens it: anything else (a
// FIFO, a file left where a camera was) could block the open or mislead the backend.
Result<void> check_camera_node(const std::string& index) {
  const std::string node = camera_node(index);
  const FileKind kind = file_kind(node);
  if (kind == FileKind::Missing)
    return fail(fmt::format("cannot open camera {}: {}: {}", index, node, std::strerror(ENOENT)));
  if (kind != FileKind::CharacterDevice)
    return fail(fmt::format("cannot open camera {}: {} is {}, not a camera's character device", index, node,
                            describe(kind)));
  return {};
}

// A camera or a video file through OpenCV's VideoCapture.
class CaptureSource final : public FrameSource {
 public:
  CaptureSource(std::string source, bool camera, bool loop)
      : source_(std::move(source)), camera_(camera), loop_(loop) {}

  Result<void> open() {
    capture_ = std::make_unique<cv::VideoCapture>();
    // The backend is named, never left to OpenCV's automatic choice: that tries every
    // backend in turn, and each failed open left memory behind inside libgphoto2/libusb
    // (33 MB over 200 restarts), which a driver retrying a missing source for days
    // turns into a growing daemon.
    const bool opened = camera_ ? capture_->open(std::stoi(source_), cv::CAP_V4L2)
                                : capture_->open(source_, cv::CAP_FFMPEG);
    if (opened && capture_->isOpened()) return {};
    if (camera_)
      return fail(fmt::format("cannot open camera {} (V4L2 {})", source_, camera_node(source_)));
    return fail(fmt::format("cannot open video file '{}' (not a video OpenCV can read)", source_));
  }

  Result<FrameRead> next() override {
    FrameRead r;  // End unless a frame is read
    if (read(r)) return r;
    if (camera_) return fail(fmt::format("camera {} stopped delivering frames", source_));
    if (frames_in_pass_ == 0)
      return fail(fmt::format("'{}': no frame could be decoded (corrupt or empty video)", source_));
    if (!loop_) return r;
    // Starts over within this read: the wrap costs no frame period.
    if (auto reopened = open(); !reopened) return std::unexpected(reopened.error());
    frames_in_pass_ = 0;
    if (read(r)) return r;
    return fail(fmt::format("'{}': no frame could be decoded after starting over", source_));
  }
  bool is_camera() const override { return camera_; }

 private:
  bool read(FrameRead& r) {
    if (!capture_->read(r.image) || r.image.empty()) return false;
    r.kind = FrameRead::Kind::Frame;
    ++frames_in_pass_;
    return true;
  }

  std::string source_;
  bool camera_;
  bool loop_;
  std::unique_ptr<cv::VideoCapture> capture_;
  std::uint64_t frames_in_pass_ = 0;
};

}  // namespace

bool is_camera_index(const std::string& s) {
  return !s.empty() && s.find_first_not_of("0123456789") == std::string::npos;
}

Result<std::unique_ptr<FrameSource>> open_frame_source(const std::string& source, bool loop) {
  if (source.empty()) return fail("no source given");
  if (names_image_files(source)) return open_image_sequence(source, loop);
  const bool camera = is_camera_index(source);
  if (camera) {
    if (auto node = check_camera_node(source); !node) return std::unexpected(node.error());
  } else {
    const FileKind kind = file_kind(source);
    if (kind == FileKind::Missing) return fail(fmt::format("video file '{}' does not exist", source));
    // A FIFO would block the open until someone wrote to it, and with it the driver.
    if (kind != FileKind::Regular)
      return fail(fmt::format("video file '{}' is {}, not a regular file", source, describe(kind)));
  }
  auto capture = std::make_unique<CaptureSource>(source, camera, loop);
  if (auto opened = capture->open(); !opened) return std::unexpected(opened.error());
  return capture;
}

Result<void> check_frame_source(const std::string& source) {
  if (is_camera_index(source)) {
    if (auto kind = check_camera_node(source); !kind) return kind;
    const std::string node = camera_node(source);
    const int fd = ::open(node.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
      return fail(fmt::format("cannot open camera {}: {}: {}", source, node, std::strerror(errno)));
    ::close(fd);
    return {};
  }
  auto opened = open_frame_source(source, false);
  if (!opened) return std::unexpected(opened.error());
  return {};
}

void to_gray8(const cv::Mat& frame, cv::Mat& gray) {
  if (frame.channels() == 3) cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  else if (frame.channels() == 4) cv::cvtColor(frame, gray, cv::COLOR_BGRA2GRAY);
  else gray = frame;
  if (gray.depth() != CV_8U) gray.convertTo(gray, CV_8U);
}

}  // namespace covtrack::fiducial
