#pragma once
// Whether an image file's bytes are whole. A JPEG or PNG cut short (a copy or an upload
// interrupted, a disk full) still decodes: libjpeg fills the missing rows with grey and
// only prints a warning, so the frame would be processed as if whole. The file's end
// marker tells: a JPEG ends with its End-Of-Image marker FF D9, a PNG with its IEND chunk.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace covtrack::fiducial {

// What is wrong with the file's bytes ("truncated JPEG: ..."), or nothing when they end
// as their format requires. Formats other than JPEG and PNG are not judged here.
std::optional<std::string> image_file_damage(const std::vector<std::uint8_t>& bytes);

}  // namespace covtrack::fiducial
