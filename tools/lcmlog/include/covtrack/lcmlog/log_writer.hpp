#pragma once
// Writes an LCM log file through LCM's own eventlog writer, so lcm-logplayer and lcm-spy
// read it, and flushes after every event so a crash loses at most the event being written.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include <lcm/eventlog.h>

#include "covtrack/protocol/result.hpp"

namespace covtrack::lcmlog {

class LogWriter {
 public:
  // Refuses an existing file unless `overwrite`.
  static Result<LogWriter> create(const std::string& path, bool overwrite);

  LogWriter(LogWriter&& other) noexcept : path_(std::move(other.path_)), log_(other.log_) {
    other.log_ = nullptr;
  }
  LogWriter& operator=(LogWriter&&) = delete;
  LogWriter(const LogWriter&) = delete;
  ~LogWriter();

  Result<void> write(std::int64_t timestamp_us, std::string_view channel,
                     std::span<const std::byte> payload);

  const std::string& path() const { return path_; }

 private:
  LogWriter(std::string path, lcm_eventlog_t* log) : path_(std::move(path)), log_(log) {}

  std::string path_;
  lcm_eventlog_t* log_ = nullptr;
};

}  // namespace covtrack::lcmlog
