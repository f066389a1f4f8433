#include "covtrack/lcmlog/log_reader.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace covtrack::lcmlog {
namespace {

std::uint64_t load_be(const std::byte* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | std::to_integer<std::uint64_t>(p[i]);
  return v;
}

}  // namespace

std::string describe(const LogDamage& d) {
  return (d.truncated ? "truncated at byte offset " : "damaged at byte offset ") +
         std::to_string(d.offset) + " (" + std::to_string(d.skipped_bytes) + " bytes " +
         (d.truncated ? "to the end of the file unreadable)" : "skipped)");
}

Result<LogReader> LogReader::open(const std::string& path) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer; it is
  // refused below like any other file that is not regular.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return fail("cannot open log '" + path + "': " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    return fail("log '" + path + "' is not a regular file");
  }
  const auto size = static_cast<std::uint64_t>(st.st_size);
  const std::byte* data = nullptr;
  if (size > 0) {
    void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (map == MAP_FAILED) {
      const int err = errno;
      ::close(fd);
      return fail("cannot map log '" + path + "': " + std::strerror(err));
    }
    ::madvise(map, size, MADV_SEQUENTIAL);
    data = static_cast<const std::byte*>(map);
  }
  ::close(fd);  // the mapping keeps the file
  return LogReader(path, data, size);
}

LogReader::LogReader(LogReader&& o) noexcept
    : path_(std::move(o.path_)), data_(o.data_), size_(o.size_), offset_(o.offset_),
      damage_(std::move(o.damage_)) {
  o.data_ = nullptr;
  o.size_ = 0;
}

LogReader::~LogReader() {
  if (data_) ::munmap(const_cast<std::byte*>(data_), size_);
}

void LogReader::rewind() {
  offset_ = 0;
  damage_.clear();
}

std::optional<LogEvent> LogReader::parse_at(std::uint64_t at) const {
  if (size_ - at < kEventHeaderBytes) return std::nullopt;
  const std::byte* p = data_ + at;
  if (load_be(p, 4) != kSyncWord) return std::nullopt;
  const auto channel_length = static_cast<std::int32_t>(load_be(p + 20, 4));
  const auto payload_length = static_cast<std::int32_t>(load_be(p + 24, 4));
  if (channel_length < 1 || channel_length > kMaxChannelLength || payload_length < 0)
    return std::nullopt;
  const std::uint64_t end = at + kEventHeaderBytes + static_cast<std::uint64_t>(channel_length) +
                            static_cast<std::uint64_t>(payload_length);
  if (end > size_) return std::nullopt;
  // A corrupted length can still land inside the file; requiring the next sync word
  // (or the end, or the start of a sync word cut by truncation) catches it.
  const std::uint64_t after = std::min<std::uint64_t>(4, size_ - end);
  if (after > 0 && load_be(data_ + end, static_cast<int>(after)) != (kSyncWord >> (8 * (4 - after))))
    return std::nullopt;
  const auto* channel = reinterpret_cast<const char*>(p + kEventHeaderBytes);
  return LogEvent{
      .event_number = static_cast<std::int64_t>(load_be(p + 4, 8)),
      .timestamp_us = static_cast<std::int64_t>(load_be(p + 12, 8)),
      .channel = std::string_view(channel, static_cast<std::size_t>(channel_length)),
      .payload = std::span<const std::byte>(p + kEventHeaderBytes + channel_length,
                                            static_cast<std::size_t>(payload_length)),
      .offset = at,
  };
}

std::optional<LogEvent> LogReader::next() {
  if (offset_ >= size_) return std::nullopt;
  auto event = parse_at(offset_);
  if (!event) {
    // Damage: look for the next sync word that starts a good event.
    const std::uint64_t damaged_at = offset_;
    const std::byte sync0{0xED};
    for (std::uint64_t at = damaged_at + 1; at < size_; ++at) {
      const void* hit = std::memchr(data_ + at, 0xED, size_ - at);
      if (!hit) break;
      at = static_cast<std::uint64_t>(static_cast<const std::byte*>(hit) - data_);
      if (data_[at] == sync0 && (event = parse_at(at))) break;
    }
    const std::uint64_t resume = event ? event->offset : size_;
    damage_.push_back({damaged_at, resume - damaged_at, !event});
    if (!event) {
      offset_ = size_;
      return std::nullopt;
    }
  }
  offset_ = event->offset + kEventHeaderBytes + event->channel.size() + event->payload.size();
  return event;
}

}  // namespace covtrack::lcmlog
