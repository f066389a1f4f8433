// `covtrack record FILE`: LCM traffic into a standard LCM log (lcm-logplayer reads it).
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <memory>
#include <optional>
#include <string>

#include <fmt/core.h>

#include "commands.hpp"
#include "covtrack/program/command_line.hpp"
#include "covtrack/lcmlog/log_writer.hpp"
#include "covtrack/lcmlog/recorder.hpp"
#include "covtrack/protocol/lcm_url.hpp"

namespace covtrack::cli {
namespace {

struct RecordArgs {
  std::string path;
  std::string channels = ".*";
  std::optional<double> duration_s;
  std::string lcm_url;
  bool force = false;
};

// SIGINT/SIGTERM write a byte here; the recorder polls the read end next to LCM's socket,
// since LCM's handle() cannot be interrupted.
int g_stop_pipe_write = -1;

void write_stop_byte(int) {
  const char byte = 1;
  [[maybe_unused]] auto ignored = ::write(g_stop_pipe_write, &byte, 1);
}

int install_stop_pipe() {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0) return -1;
  g_stop_pipe_write = fds[1];
  struct sigaction action {};
  action.sa_handler = write_stop_byte;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
  return fds[0];
}

void print_summary(const lcmlog::RecordSummary& s, const std::string& path) {
  fmt::print(stderr, "covtrack record: {} events, {} bytes in {:.2f} s -> {}\n", s.events, s.bytes,
             s.duration_s, path);
  for (const auto& [channel, count] : s.events_per_channel)
    fmt::print(stderr, "  {:<63} {}\n", channel, count);
  if (s.restamped > 0)
    fmt::print(stderr, "covtrack record: {} events arrived stamped earlier than the event before them; "
                       "written with that event's time, so the log is in time order\n", s.restamped);
  if (s.bad_messages.total > 0)
    fmt::print(stderr, "covtrack record: warning: messages that fail the covtrack wire checks, recorded as they came: {}\n",
               s.bad_messages.summary());
}

int run_record(const RecordArgs& args) {
  auto lcm = open_lcm(args.lcm_url);
  if (!lcm) {
    fmt::print(stderr, "covtrack record: {}\n", lcm.error().message);
    return 1;
  }
  auto writer = lcmlog::LogWriter::create(args.path, args.force);
  if (!writer) {
    fmt::print(stderr, "covtrack record: {}\n", writer.error().message);
    return 1;
  }
  const int stop_fd = install_stop_pipe();
  auto recorder = lcmlog::Recorder::start(**lcm, *writer, args.channels);
  if (!recorder) {
    fmt::print(stderr, "covtrack record: {}\n", recorder.error().message);
    return 1;
  }
  // Scripts and tests wait for this line: from here on every message is recorded.
  fmt::print(stderr, "covtrack record: recording channels '{}' on {} to {} (Ctrl-C stops)\n",
             args.channels, effective_lcm_url(args.lcm_url), args.path);
  auto summary = (*recorder)->run(stop_fd, args.duration_s);
  if (!summary) {
    fmt::print(stderr, "covtrack record: {}\n", summary.error().message);
    return 1;
  }
  print_summary(*summary, args.path);
  return 0;
}

}  // namespace

void add_record_command(CLI::App& app) {
  auto args = std::make_shared<RecordArgs>();
  auto* cmd = app.add_subcommand("record", "Record LCM traffic into an LCM log file");
  cmd->add_option("FILE", args->path, "Log file to write (standard LCM log format)")->required();
  cmd->add_option("--channels", args->channels,
                  "POSIX extended regular expression over whole channel names (covtrack/pose/.*)")
      ->capture_default_str();
  cmd->add_option("--duration,-d", args->duration_s, "Stop after S seconds")
      ->check(program::positive());
  cmd->add_option("--lcm-url,-u", args->lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or LCM's)");
  cmd->add_flag("--force,-f", args->force, "Overwrite FILE if it exists");
  cmd->callback([args] {
    if (const int code = run_record(*args); code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace covtrack::cli
