#include "covtrack/devices/file_kind.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

namespace covtrack {
namespace {

FileKind kind_of(mode_t mode) {
  if (S_ISREG(mode)) return FileKind::Regular;
  if (S_ISDIR(mode)) return FileKind::Folder;
  if (S_ISFIFO(mode)) return FileKind::Fifo;
  if (S_ISCHR(mode)) return FileKind::CharacterDevice;
  if (S_ISBLK(mode)) return FileKind::BlockDevice;
  if (S_ISSOCK(mode)) return FileKind::Socket;
  return FileKind::Other;
}

}  // namespace

FileKind file_kind(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return FileKind::Missing;
  return kind_of(st.st_mode);
}

std::string_view describe(FileKind kind) {
  switch (kind) {
    case FileKind::Missing: return "missing";
    case FileKind::Regular: return "a regular file";
    case FileKind::Folder: return "a folder";
    case FileKind::Fifo: return "a FIFO (named pipe)";
    case FileKind::CharacterDevice: return "a character device";
    case FileKind::BlockDevice: return "a block device";
    case FileKind::Socket: return "a socket";
    case FileKind::Other: return "of an unknown kind";
  }
  return "?";
}

Result<void> require_character_device(const std::string& path, std::string_view what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return fail(fmt::format("{} '{}' cannot be used: {}", what, path, std::strerror(errno)));
  const FileKind kind = kind_of(st.st_mode);
  if (kind == FileKind::CharacterDevice) return {};
  return fail(fmt::format("{} '{}' is {}, not a character device", what, path, describe(kind)));
}

}  // namespace covtrack
