#include "image_sequence.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "covtrack/devices/file_kind.hpp"
#include "image_file_check.hpp"

namespace covtrack::fiducial {
namespace {

namespace fs = std::filesystem;

// The whole file, or why it cannot be read. Checked to be a regular file before it is
// opened: a FIFO in its place would block the driver (and a stop request) until someone
// wrote to it, and opening a device can have effects. Opened without blocking and
// checked again, should the file have been replaced in between.
Result<std::vector<std::uint8_t>> read_regular_file(const std::string& name) {
  if (const FileKind kind = file_kind(name); kind != FileKind::Regular && kind != FileKind::Missing)
    return fail(fmt::format("is {}, not a regular file", describe(kind)));
  const int fd = ::open(name.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return fail(fmt::format("cannot be read ({})", std::strerror(errno)));
  std::vector<std::uint8_t> bytes;
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return fail("is no longer a regular file");
  }
  bytes.reserve(static_cast<std::size_t>(st.st_size));
  std::uint8_t chunk[65536];
  for (;;) {
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n > 0) {
      bytes.insert(bytes.end(), chunk, chunk + n);
    } else if (n == 0) {
      break;
    } else if (errno != EINTR) {
      const int error = errno;
      ::close(fd);
      return fail(fmt::format("cannot be read ({})", std::strerror(error)));
    }
  }
  ::close(fd);
  return bytes;
}

// A file name pattern with one printf-style integer field, as OpenCV's sequence reader
// takes them ("frame_%04d.png"); parsed rather than handed to printf, so that a stray
// %s in a config cannot read memory.
struct FilePattern {
  std::string prefix, suffix;
  int width = 0;
  bool zero_pad = false;
  bool numbered = false;  // false: one still image, named by prefix

  std::string name(int index) const {
    if (!numbered) return prefix;
    const std::string number = zero_pad ? fmt::format("{:0{}d}", index, width)
                                         : fmt::format("{:>{}d}", index, width);
    return prefix + number + suffix;
  }
};

Result<FilePattern> parse_pattern(const std::string& source) {
  FilePattern p;
  const auto percent = source.find('%');
  if (percent == std::string::npos) {
    p.prefix = source;
    return p;
  }
  std::size_t i = percent + 1;
  if (i < source.size() && source[i] == '0') p.zero_pad = true, ++i;
  const std::size_t digits = i;
  while (i < source.size() && std::isdigit(static_cast<unsigned char>(source[i]))) ++i;
  // Widths over 32 are taken as 32; one too long for an int is too (std::stoi threw on it,
  // which ended `covtrackd --check`).
  if (i > digits) p.width = i - digits > 2 ? 32 : std::min(std::stoi(source.substr(digits, i - digits)), 32);
  if (i >= source.size() || source[i] != 'd' || source.find('%', i) != std::string::npos)
    return fail(fmt::format("image sequence '{}': the pattern must hold exactly one %d field, "
                            "e.g. frame_%04d.png", source));
  p.prefix = source.substr(0, percent);
  p.suffix = source.substr(i + 1);
  p.numbered = true;
  return p;
}

class ImageSequence final : public FrameSource {
 public:
  ImageSequence(std::string source, FilePattern pattern, int first, bool loop)
      : source_(std::move(source)), pattern_(std::move(pattern)), first_(first), index_(first),
        loop_(loop) {}

  Result<FrameRead> next() override {
    if (!has(index_)) {
      if (index_ == first_)
        return fail(fmt::format("{}: its first file '{}' is gone", what(), pattern_.name(first_)));
      if (!loop_) return FrameRead{};
      index_ = first_;  // starts over within this read: the wrap costs no frame period
      if (!has(index_))
        return fail(fmt::format("{}: its first file '{}' is gone", what(), pattern_.name(first_)));
    }
    return read(pattern_.name(index_++));
  }
  bool is_camera() const override { return false; }

 private:
  bool has(int index) const {
    return (pattern_.numbered || index == first_) && fs::exists(pattern_.name(index));
  }
  std::string what() const {
    return fmt::format("{} '{}'", pattern_.numbered ? "image sequence" : "image file", source_);
  }

  static Result<FrameRead> read(const std::string& name) {
    FrameRead r;
    r.name = name;
    const auto bytes = read_regular_file(name);
    if (!bytes) {
      r.kind = FrameRead::Kind::Damaged;
      r.problem = bytes.error().message;
      return r;
    }
    if (auto damage = image_file_damage(*bytes)) {
      r.kind = FrameRead::Kind::Damaged;
      r.problem = *damage;
      return r;
    }
    r.image = cv::imdecode(*bytes, cv::IMREAD_UNCHANGED);
    if (r.image.empty()) {
      r.kind = FrameRead::Kind::Damaged;
      r.problem = "not an image OpenCV can decode";
      return r;
    }
    r.kind = FrameRead::Kind::Frame;
    return r;
  }

  std::string source_;
  FilePattern pattern_;
  int first_;
  int index_;
  bool loop_;
};

}  // namespace

bool names_image_files(const std::string& source) {
  if (source.find('%') != std::string::npos) return true;
  std::string ext = fs::path(source).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const char* e : {".png", ".jpg", ".jpeg", ".bmp", ".pgm", ".ppm", ".tif", ".tiff", ".webp"})
    if (ext == e) return true;
  return false;
}

Result<std::unique_ptr<FrameSource>> open_image_sequence(const std::string& source, bool loop) {
  auto pattern = parse_pattern(source);
  if (!pattern) return std::unexpected(pattern.error());
  const char* what = pattern->numbered ? "image sequence" : "image file";
  const fs::path folder = fs::path(pattern->name(0)).parent_path();
  if (!folder.empty() && !fs::is_directory(folder))
    return fail(fmt::format("{} '{}': folder '{}' does not exist", what, source, folder.string()));
  // Numbered files start at 0 or 1, as with OpenCV's sequence reader.
  int first = 0;
  if (!fs::exists(pattern->name(0))) {
    if (!pattern->numbered)
      return fail(fmt::format("image file '{}' does not exist", source));
    if (!fs::exists(pattern->name(1)))
      return fail(fmt::format("image sequence '{}': neither '{}' nor '{}' exists", source,
                              pattern->name(0), pattern->name(1)));
    first = 1;
  }
  if (auto readable = read_regular_file(pattern->name(first)); !readable)
    return fail(fmt::format("{} '{}': '{}' {}", what, source, pattern->name(first), readable.error().message));
  return std::make_unique<ImageSequence>(source, *pattern, first, loop);
}

}  // namespace covtrack::fiducial
