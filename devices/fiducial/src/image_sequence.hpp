#pragma once
// Image files as a frame source (frame_source.hpp): a numbered pattern or one still image.
#include <memory>
#include <string>

#include "frame_source.hpp"

namespace covtrack::fiducial {

// True when `source` names image files rather than a video: it holds a '%' (a
// pattern) or ends in an image file's extension.
bool names_image_files(const std::string& source);

Result<std::unique_ptr<FrameSource>> open_image_sequence(const std::string& source, bool loop);

}  // namespace covtrack::fiducial
