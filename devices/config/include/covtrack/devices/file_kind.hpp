#pragma once
// What kind of file a path names, checked before a driver opens it. Opening a FIFO
// blocks until someone opens its other end, and reading a device that is not the one
// expected can block or never end; a driver would then miss a stop request, so the
// kind is checked first and a wrong one is an error that says what the path is.
#include <string>
#include <string_view>

#include "covtrack/protocol/result.hpp"

namespace covtrack {

enum class FileKind { Missing, Regular, Folder, Fifo, CharacterDevice, BlockDevice, Socket, Other };

// Follows symbolic links.
FileKind file_kind(const std::string& path);
// "a FIFO (named pipe)", "a folder", ...
std::string_view describe(FileKind kind);

// An error "<what> '<path>' is a FIFO (named pipe), not a character device" unless it is one.
Result<void> require_character_device(const std::string& path, std::string_view what);

}  // namespace covtrack
