#pragma once
// Where the fiducial driver's frames come from: a V4L2 camera, a video file, or image
// files (a numbered pattern such as "frames/frame_%04d.png", or one still image).
// Image files are read here rather than by OpenCV's sequence reader so that a damaged
// file is named and skipped instead of processed half grey (image_file_check.hpp), and
// so that a looped sequence starts over within one read: the wrap costs no frame period.
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "covtrack/protocol/result.hpp"

namespace covtrack::fiducial {

struct FrameRead {
  enum class Kind { Frame, Damaged, End };
  Kind kind = Kind::End;
  cv::Mat image;        // Frame: as decoded (colour if the file is)
  std::string name;     // the file read, for image files (empty for cameras and videos)
  std::string problem;  // Damaged: what is wrong with the file
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame. At the end of a file source: with loop, the first frame again (in
  // this same call); without, End. An error when the source cannot go on (a camera that
  // stopped, files that went away, a video of which no frame decodes).
  virtual Result<FrameRead> next() = 0;
  virtual bool is_camera() const = 0;
};

// All digits: V4L2 camera index.
bool is_camera_index(const std::string& source);

// Opens `source`: a camera index; a pattern holding one %d (%04d ...) or a file with an
// image extension (.png .jpg .jpeg .bmp .pgm .ppm .tif .tiff .webp): image files; any
// other path: a video file. Errors say what the source was taken for and where it was
// looked for ("image sequence 'd/f_%04d.png': folder 'd' does not exist"). Nothing is
// opened that could block: image and video files must be regular files and a camera's
// node a character device, checked first. Cameras are read through OpenCV's V4L2
// backend and videos through its FFmpeg one, never its automatic choice (which leaks
// on every failed open).
Result<std::unique_ptr<FrameSource>> open_frame_source(const std::string& source, bool loop);

// What `covtrackd --check` asks of a source: that it opens. A camera is only opened as
// a device node, not streamed, so the check does not disturb a daemon already using it.
Result<void> check_frame_source(const std::string& source);

// A frame as the detector takes it: 8-bit grey (colour converted, other depths scaled
// down), into `gray` so a caller's buffer is reused from frame to frame.
void to_gray8(const cv::Mat& frame, cv::Mat& gray);

}  // namespace covtrack::fiducial
