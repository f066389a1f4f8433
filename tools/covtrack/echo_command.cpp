// `covtrack echo [PATTERN]`: a live table of the pose streams, or one JSON object per
// message with --json.
#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <atomic>
#include <iostream>
#include <map>
#include <numbers>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "covtrack/program/command_line.hpp"
#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/lcm_url.hpp"
#include "covtrack/protocol/wire_text.hpp"
#include "stop_signal.hpp"
#include "subscriber_summary.hpp"

namespace covtrack::cli {
namespace {

struct EchoOptions {
  client::SubscriberOptions subscriber;
  bool json = false;
  long count = 0;         // 0: no limit
  double duration_s = 0;  // 0: no limit
};

// 1-sigma along the worst direction: the square root of the block's largest eigenvalue.
double worst_sigma(const Mat6& cov, int block) {
  const Mat3 b = cov.block<3, 3>(3 * block, 3 * block);
  return std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Mat3>(b).eigenvalues()(2)));
}

nlohmann::json to_json(const client::TrackedTransform& t) {
  Eigen::Quaterniond q(t.T_parent_child.linear());
  if (q.w() < 0) q.coeffs() = -q.coeffs();  // the wire's canonical sign
  nlohmann::json j = {
      {"device", t.stream.device}, {"sensor", t.stream.sensor},
      {"parent_frame", t.parent_frame}, {"child_frame", t.child_frame},
      {"sequence", t.sequence}, {"status", to_string(t.status)},
      {"measurement_time_us", t.measurement_time_us}, {"publish_time_us", t.publish_time_us},
      {"receive_time_us", t.receive_time_us},
      {"position_m", {t.T_parent_child.translation().x(), t.T_parent_child.translation().y(),
                      t.T_parent_child.translation().z()}},
      {"orientation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
      {"covariance_convention", "BODY"},
      {"device_unreachable", t.device_unreachable}};
  if (t.lost()) {
    j["covariance"] = nullptr;  // infinite: JSON has no infinity
  } else {
    std::vector<double> c;  // row-major, as on the wire
    for (int r = 0; r < 6; ++r)
      for (int k = 0; k < 6; ++k) c.push_back(t.covariance(r, k));
    j["covariance"] = c;
  }
  return j;
}

// Rate per stream from the change of its received counter between two tables.
class RateMeter {
 public:
  explicit RateMeter(double start_s) : start_s_(start_s) {}
  double update(const std::string& key, std::int64_t received, double now_s) {
    // A stream first seen now started counting when echo started.
    auto& [last_count, last_time] = last_.try_emplace(key, 0, start_s_).first->second;
    const double rate = now_s > last_time ? (received - last_count) / (now_s - last_time) : 0;
    last_count = received;
    last_time = now_s;
    return rate;
  }

 private:
  double start_s_;
  std::map<std::string, std::pair<std::int64_t, double>> last_;
};

// How long echo waits for a first message before it says that nothing arrives.
constexpr std::chrono::seconds kSilenceHint{3};

constexpr const char* kRowFormat = "{:<28} {:>8} {:>26} {:>9} {:>9} {:<8} {:>6} {:>6} {:>7} {:>7} {:<5} {:>5}\n";

// One device's heartbeat: its counters, who publishes it, and what its heartbeats reveal.
std::string device_line(const std::string& name, const client::DeviceState& d) {
  const device_status_t& st = d.status;
  std::string line = fmt::format("device {:<20} {:>7.1f} Hz reports {:>9} errors {:>4} drops {:>4} restarts {:>3}  "
                                 "from {}:{}", name, st.rate_hz, st.reports, st.errors, st.drops, st.restarts,
                                 st.host, st.pid);
  if (!d.reachable)
    line += fmt::format("  UNREACHABLE: no heartbeat for {:.1f} s, its streams LOST",
                        1e-6 * static_cast<double>(now_us() - d.last_heard_us));
  if (d.publishers > 1) line += "  " + client::second_publisher_warning(name, d);
  if (d.restarts > 0) line += fmt::format("  daemon restarted {} time(s)", d.restarts);
  if (!st.detail.empty()) line += "  (" + printable(st.detail) + ")";
  if (!st.last_error.empty()) line += "  last error: " + printable(st.last_error);
  return line + "\n";
}

// Once per device and set of publishers, on stderr (also in --json mode, which has no table).
void warn_second_publishers(const client::Subscriber& sub, std::set<std::string>& warned) {
  for (const auto& [name, device] : sub.devices()) {
    const std::string warning = client::second_publisher_warning(name, device);
    if (!warning.empty() && warned.insert(warning).second) std::cerr << "covtrack echo: " << warning << "\n";
  }
}

double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string table(const client::Subscriber& sub, RateMeter& rates) {
  std::string out = fmt::format(fmt::runtime(kRowFormat), "stream", "rate Hz", "position m (x y z)",
                                "σpos mm", "σrot deg", "status", "lost", "reject", "foreign", "restart", "stale",
                                "times");
  const double now_s = steady_now_s();
  for (const auto& s : sub.streams()) {
    const double rate = rates.update(s.id.key(), s.counters.received, now_s);
    std::string position = "-", sp = "-", sr = "-", status = "-";
    if (s.latest) {
      const Vec3 p = s.latest->T_parent_child.translation();
      position = fmt::format("{:8.4f} {:8.4f} {:8.4f}", p.x(), p.y(), p.z());
      status = to_string(s.latest->status);
      if (!s.latest->lost()) {
        sp = fmt::format("{:.3f}", 1e3 * worst_sigma(s.latest->covariance, 0));
        sr = fmt::format("{:.3f}", worst_sigma(s.latest->covariance, 1) * 180 / std::numbers::pi);
      } else {
        sp = sr = "inf";
      }
    }
    out += fmt::format(fmt::runtime(kRowFormat), s.id.key(), fmt::format("{:.1f}", rate), position, sp,
                       sr, status, s.counters.lost, s.counters.rejected, s.counters.foreign, s.counters.restarts,
                       s.stale ? "STALE" : "", s.counters.stale);
  }
  out += "σ: 1-sigma along the worst direction (sqrt of the largest eigenvalue of the 3x3 "
         "position / rotation block, BODY frame); foreign: messages off the stream's sequence "
         "(a second publisher, forged, duplicate); restart: the sequence started again; stale "
         "times: how often it went stale\n";
  out += authentication_line(sub);
  if (const RejectionTally rejected = sub.rejections(); rejected.total > 0)
    out += "rejected messages: " + rejected.summary() + "\n";
  for (const auto& [name, device] : sub.devices()) out += device_line(name, device);
  return out;
}

// Ends on SIGINT/SIGTERM, --count messages or --duration seconds.
int run_echo(const EchoOptions& o) {
  install_stop_signals();
  auto sub = client::Subscriber::open(o.subscriber);
  if (!sub) {
    std::cerr << "covtrack echo: " << sub.error().message << "\n";
    return 1;
  }
  // Scripts and tests wait for this line: from here on every message is seen.
  const auto auth = (*sub)->authentication();
  std::cerr << fmt::format("covtrack echo: listening on {} for streams '{}'{} (Ctrl-C ends)\n",
                           effective_lcm_url(o.subscriber.lcm_url), o.subscriber.pattern,
                           auth ? ", authenticated messages only (key " + auth->key_file + ")" : "");
  std::cerr << receive_buffer_warning(**sub, "covtrack echo: ");
  std::atomic<long> seen{0};
  // Runs on the subscriber's dispatch thread, the only writer of stdout in --json mode.
  (void)(*sub)->on_pose(".*", [&](const client::TrackedTransform& t) {
    if (o.count > 0 && seen >= o.count) return;
    // The wire checks let only UTF-8 through; `replace` keeps a slip there from ending echo.
    if (o.json) std::cout << to_json(t).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n" << std::flush;
    ++seen;
  });
  // With no daemon on this URL echo would wait in silence: say so once, on stderr.
  const auto hint_at = std::chrono::steady_clock::now() + kSilenceHint;
  bool hinted = false;
  const bool tty = ::isatty(STDOUT_FILENO);
  const auto start = std::chrono::steady_clock::now();
  auto next_table = start + std::chrono::milliseconds(tty ? 200 : 1000);
  RateMeter rates(steady_now_s());
  std::set<std::string> warned;
  auto print_table = [&] {
    const std::string t = table(**sub, rates);
    if (tty) std::cout << "\x1b[H\x1b[2J";  // redraw in place
    std::cout << t << (tty ? "" : "\n") << std::flush;
  };
  while (!stop_requested()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto now = std::chrono::steady_clock::now();
    if (o.count > 0 && seen >= o.count) break;
    if (o.duration_s > 0 && now - start >= std::chrono::duration<double>(o.duration_s)) break;
    if (!hinted && now >= hint_at) {
      hinted = true;
      if ((*sub)->streams().empty() && (*sub)->devices().empty() && (*sub)->rejections().total == 0)
        std::cerr << fmt::format("covtrack echo: nothing received for {} s on {} (streams '{}'): is covtrackd "
                                 "running and publishing there? (covtrackd --config config/sim.toml); still waiting, Ctrl-C ends\n",
                                 kSilenceHint.count(), effective_lcm_url(o.subscriber.lcm_url),
                                 o.subscriber.pattern);
    }
    warn_second_publishers(**sub, warned);
    if (!o.json && now >= next_table) {
      next_table += std::chrono::milliseconds(tty ? 200 : 1000);
      print_table();
    }
  }
  (*sub)->stop();
  std::cerr << subscriber_summary(**sub, "covtrack echo: ");
  return 0;
}

}  // namespace

void add_echo_command(CLI::App& app) {
  auto o = std::make_shared<EchoOptions>();
  auto* cmd = app.add_subcommand("echo", "show pose streams live (table, or JSON per message)");
  cmd->add_option("pattern", o->subscriber.pattern,
                  "POSIX extended regular expression over device/sensor, whole match (default: all)");
  cmd->add_flag("--json,-j", o->json, "one JSON object per message, one per line");
  cmd->add_option("--lcm-url,-u", o->subscriber.lcm_url, "LCM URL");
  add_key_file_option(*cmd, o->subscriber.key_file);
  cmd->add_option("--stale", o->subscriber.stale_after_s, "seconds without a message before a stream is stale")
      ->check(program::positive());
  cmd->add_option("--count,-n", o->count, "exit after this many accepted messages")->check(program::non_negative());
  cmd->add_option("--duration,-d", o->duration_s, "exit after this many seconds")->check(program::non_negative());
  cmd->callback([o] {
    if (const int rc = run_echo(*o); rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace covtrack::cli
