// `covtrack replay FILE`: publishes an LCM log with its original timing.
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "commands.hpp"
#include "covtrack/program/command_line.hpp"
#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/lcmlog/replayer.hpp"
#include "covtrack/protocol/lcm_url.hpp"
#include "stop_signal.hpp"

namespace covtrack::cli {
namespace {

struct ReplayArgs {
  std::string path;
  lcmlog::ReplayOptions options;
  std::string lcm_url;
};

// One line rewritten in place at most 10 times a second; only on a terminal, so logs of
// scripted runs stay clean.
class ProgressLine {
 public:
  ProgressLine() : enabled_(::isatty(STDERR_FILENO) == 1) {}
  void update(const lcmlog::ReplayProgress& p, bool force = false) {
    if (!enabled_) return;
    last_progress_ = p;
    const auto now = std::chrono::steady_clock::now();
    if (!force && shown_ && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    shown_ = true;
    const double percent = p.size ? 100.0 * static_cast<double>(p.offset) / p.size : 100.0;
    fmt::print(stderr, "\rreplay: {} events, log time {:.1f} s, {:.0f}% of file\x1b[K",
               p.events_published, p.log_time_s, percent);
  }
  // The final figures, then leave the line.
  void finish() {
    if (!shown_) return;
    update(last_progress_, true);
    fmt::print(stderr, "\n");
  }

 private:
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point last_;
  lcmlog::ReplayProgress last_progress_{};
};

int run_replay(const ReplayArgs& args) {
  auto reader = lcmlog::LogReader::open(args.path);
  if (!reader) {
    fmt::print(stderr, "covtrack replay: {}\n", reader.error().message);
    return 1;
  }
  auto lcm = open_lcm(args.lcm_url);
  if (!lcm) {
    fmt::print(stderr, "covtrack replay: {}\n", lcm.error().message);
    return 1;
  }
  install_stop_signals();
  ProgressLine progress;
  auto summary = lcmlog::replay(*reader, **lcm, args.options, stop_requested(),
                                [&](const lcmlog::ReplayProgress& p) { progress.update(p); });
  progress.finish();
  if (!summary) {
    fmt::print(stderr, "covtrack replay: {}\n", summary.error().message);
    return 1;
  }
  fmt::print(stderr, "covtrack replay: published {} events ({} payload bytes){}\n",
             summary->events_published, summary->payload_bytes,
             summary->stopped ? ", stopped" : "");
  if (summary->bad_messages.total > 0)
    fmt::print(stderr, "covtrack replay: warning: messages that fail the covtrack wire checks, published as they are: {}\n",
               summary->bad_messages.summary());
  if (summary->damage.empty()) return 0;
  for (const auto& damage : summary->damage)
    fmt::print(stderr, "covtrack replay: warning: log '{}' {}\n", args.path,
               lcmlog::describe(damage));
  fmt::print(stderr,
             "covtrack replay: warning: the log is damaged; {} events before and between the "
             "damaged ranges were replayed\n",
             summary->events_published);
  return program::kExitDamagedInput;  // scripts notice; all before the damage was published
}

}  // namespace

void add_replay_command(CLI::App& app) {
  auto args = std::make_shared<ReplayArgs>();
  auto* cmd = app.add_subcommand("replay", "Publish the events of an LCM log file");
  cmd->add_option("FILE", args->path, "LCM log file")->required();
  cmd->add_option("--speed,-s", args->options.speed, "Speed factor; 0 = as fast as possible")
      ->capture_default_str()
      ->check(program::non_negative());
  cmd->add_flag("--loop", args->options.loop, "Start again at the end, until interrupted");
  cmd->add_option("--start", args->options.start_s, "Skip the first S seconds of the log")
      ->check(program::non_negative());
  cmd->add_option("--channels", args->options.channels,
                  "POSIX extended regular expression over whole channel names (covtrack/pose/.*)")
      ->capture_default_str();
  cmd->add_option("--lcm-url,-u", args->lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or LCM's)");
  cmd->callback([args] {
    if (const int code = run_replay(*args); code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace covtrack::cli
