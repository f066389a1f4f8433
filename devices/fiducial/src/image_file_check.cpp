#include "image_file_check.hpp"

#include <algorithm>
#include <array>

#include <fmt/format.h>

namespace covtrack::fiducial {
namespace {

bool starts_with(const std::vector<std::uint8_t>& bytes, const std::uint8_t* head, std::size_t n) {
  return bytes.size() >= n && std::equal(head, head + n, bytes.begin());
}

}  // namespace

std::optional<std::string> image_file_damage(const std::vector<std::uint8_t>& bytes) {
  static constexpr std::uint8_t kJpegStart[] = {0xFF, 0xD8};
  static constexpr std::uint8_t kPngSignature[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  // Length 0, "IEND", and the CRC of "IEND": the PNG's last 12 bytes, always the same.
  static constexpr std::array<std::uint8_t, 12> kPngEnd = {0, 0, 0, 0, 'I', 'E', 'N', 'D',
                                                           0xAE, 0x42, 0x60, 0x82};
  if (bytes.empty()) return "empty file";
  if (starts_with(bytes, kJpegStart, sizeof kJpegStart)) {
    // Some cameras pad a JPEG with zero bytes after its end marker; that is whole.
    std::size_t end = bytes.size();
    while (end > 2 && bytes[end - 1] == 0) --end;
    if (end >= 4 && bytes[end - 2] == 0xFF && bytes[end - 1] == 0xD9) return std::nullopt;
    return fmt::format("truncated JPEG: {} bytes and no End-Of-Image marker (FF D9) at the end",
                       bytes.size());
  }
  if (starts_with(bytes, kPngSignature, sizeof kPngSignature)) {
    if (bytes.size() >= sizeof kPngSignature + kPngEnd.size() &&
        std::equal(kPngEnd.begin(), kPngEnd.end(), bytes.end() - kPngEnd.size()))
      return std::nullopt;
    return fmt::format("truncated PNG: {} bytes and no IEND chunk at the end", bytes.size());
  }
  return std::nullopt;
}

}  // namespace covtrack::fiducial
