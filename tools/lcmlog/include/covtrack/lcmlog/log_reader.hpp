#pragma once
// Reads an LCM log file (no header; each event: sync word 0xEDA1DA01, big-endian numbers,
// channel name, payload) event by event and says where it is damaged. LCM's own reader
// (lcm_eventlog_read_next_event) skips garbage silently and asserts on a bad channel
// length, so it can report neither a truncation nor a corruption: this one validates
// every event and reports each damaged byte range.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "covtrack/protocol/result.hpp"

namespace covtrack::lcmlog {

inline constexpr std::uint32_t kSyncWord = 0xEDA1DA01;
inline constexpr std::size_t kEventHeaderBytes = 4 + 8 + 8 + 4 + 4;
inline constexpr std::int32_t kMaxChannelLength = 999;  // LCM's readers reject >= 1000

// Views into the mapped file: valid until the reader is destroyed.
struct LogEvent {
  std::int64_t event_number;
  std::int64_t timestamp_us;
  std::string_view channel;
  std::span<const std::byte> payload;
  std::uint64_t offset;  // of its sync word
};

struct LogDamage {
  std::uint64_t offset;         // first byte that is not part of a good event
  std::uint64_t skipped_bytes;  // up to the next good event, or to the end of the file
  bool truncated;               // the damage runs to the end of the file
};

std::string describe(const LogDamage& damage);

class LogReader {
 public:
  // The whole file is mapped read-only: replay touches each byte once, and events come
  // out as views without a copy.
  static Result<LogReader> open(const std::string& path);

  LogReader(LogReader&& other) noexcept;
  LogReader& operator=(LogReader&&) = delete;
  LogReader(const LogReader&) = delete;
  ~LogReader();

  // The next good event, or nothing at the end of the file. Damage passed on the way
  // (garbage before a good event, or a truncated / unreadable tail) is recorded in
  // damage(); reading resynchronises on the next sync word that starts a good event.
  std::optional<LogEvent> next();

  // Back to the first byte; the damage list is cleared (a second pass finds it again).
  void rewind();

  const std::vector<LogDamage>& damage() const { return damage_; }
  std::uint64_t size() const { return size_; }
  std::uint64_t offset() const { return offset_; }
  const std::string& path() const { return path_; }

 private:
  LogReader(std::string path, const std::byte* data, std::uint64_t size)
      : path_(std::move(path)), data_(data), size_(size) {}

  // The event starting at `at` if it is well formed: a sync word, a plausible header,
  // the whole body inside the file, and followed by the next sync word or the end.
  std::optional<LogEvent> parse_at(std::uint64_t at) const;

  std::string path_;
  const std::byte* data_ = nullptr;
  std::uint64_t size_ = 0;
  std::uint64_t offset_ = 0;
  std::vector<LogDamage> damage_;
};

}  // namespace covtrack::lcmlog
