#include "covtrack/lcmlog/log_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace covtrack::lcmlog {

Result<LogWriter> LogWriter::create(const std::string& path, bool overwrite) {
  if (!overwrite) {
    // O_EXCL reserves the name atomically: a check-then-create could clobber a file
    // that another recorder created in between.
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0 && errno == EEXIST)
      return fail("'" + path + "' already exists; pass --force to overwrite it");
    if (fd < 0) return fail("cannot create log '" + path + "': " + std::strerror(errno));
    ::close(fd);
  }
  errno = 0;
  lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "w");
  if (!log)
    return fail("cannot create log '" + path + "': " +
                (errno ? std::strerror(errno) : "lcm_eventlog_create failed"));
  return LogWriter(path, log);
}

LogWriter::~LogWriter() {
  if (log_) lcm_eventlog_destroy(log_);
}

Result<void> LogWriter::write(std::int64_t timestamp_us, std::string_view channel,
                              std::span<const std::byte> payload) {
  lcm_eventlog_event_t event{};
  event.timestamp = timestamp_us;
  event.channellen = static_cast<std::int32_t>(channel.size());
  event.datalen = static_cast<std::int32_t>(payload.size());
  // LCM's API is not const-correct; it only reads these buffers.
  event.channel = const_cast<char*>(channel.data());
  event.data = const_cast<std::byte*>(payload.data());
  if (lcm_eventlog_write_event(log_, &event) != 0 || std::fflush(log_->f) != 0)
    return fail("writing log '" + path_ + "' failed: " + std::strerror(errno));
  return {};
}

}  // namespace covtrack::lcmlog
