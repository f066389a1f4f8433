// `covtrack echo [PATTERN]`: a live table of the pose streams, or one JSON object per
// message with --json.
#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <mutex>
#include <numbers>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/clock.hpp"
#include "stop_signal.hpp"

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
  const Eigen::Quaterniond q(t.T_parent_child.linear());
  nlohmann::json j = {
      {"device", t.stream.device}, {"sensor", t.stream.sensor},
      {"parent_frame", t.parent_frame}, {"child_frame", t.child_frame},
      {"sequence", t.sequence}, {"status", to_string(t.status)},
      {"measurement_time_us", t.measurement_time_us}, {"publish_time_us", t.publish_time_us},
      {"receive_time_us", t.receive_time_us},
      {"position_m", {t.T_parent_child.translation().x(), t.T_parent_child.translation().y(),
                      t.T_parent_child.translation().z()}},
      {"orientation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
      {"covariance_convention", "BODY"}};
  if (t.lost()) {
    j["covariance"] = nullptr;  // infinite: JSON has no infinity
  } else {
    std::vector<double> c(t.covariance.data(), t.covariance.data() + 36);  // symmetric
    j["covariance"] = c;
  }
  return j;
}

std::string table(const client::Subscriber& sub, std::map<std::string, std::pair<long, double>>& rates) {
  std::string out = fmt::format("{:<28} {:>8} {:>27} {:>10} {:>9} {:<9} {:>6} {:>6}\n", "stream",
                                "rate Hz", "position m", "σpos mm", "σrot deg", "status", "lost",
                                "reject");
  const auto now = std::chrono::steady_clock::now().time_since_epoch();
  const double now_s = std::chrono::duration<double>(now).count();
  for (const auto& s : sub.streams()) {
    auto& [last_count, last_time] = rates[s.id.key()];
    const double rate = last_time > 0 ? (s.counters.received - last_count) / (now_s - last_time) : 0;
    last_count = s.counters.received;
    last_time = now_s;
    std::string position = "-", sp = "-", sr = "-", status = "-";
    if (s.latest) {
      const Vec3 p = s.latest->T_parent_child.translation();
      position = fmt::format("{:8.4f} {:8.4f} {:8.4f}", p.x(), p.y(), p.z());
      status = to_string(s.latest->status);
      if (!s.latest->lost()) {
        sp = fmt::format("{:.3f}", 1e3 * worst_sigma(s.latest->covariance, 0));
        sr = fmt::format("{:.3f}", worst_sigma(s.latest->covariance, 1) * 180 / std::numbers::pi);
      }
    }
    if (s.stale) status = "STALE";
    out += fmt::format("{:<28} {:>8.1f} {:>27} {:>10} {:>9} {:<9} {:>6} {:>6}\n", s.id.key(), rate,
                       position, sp, sr, status, s.counters.lost, s.counters.rejected);
  }
  for (const auto& [device, st] : sub.device_statuses())
    out += fmt::format("device {:<20} reports {:>9} errors {:>4} drops {:>4} restarts {:>3}{}\n",
                       device, st.reports, st.errors, st.drops, st.restarts,
                       st.last_error.empty() ? "" : "  last error: " + st.last_error);
  return out;
}

int run_echo(const EchoOptions& o) {
  install_stop_signals();
  auto sub = client::Subscriber::open(o.subscriber);
  if (!sub) {
    std::cerr << "covtrack echo: " << sub.error().message << "\n";
    return 1;
  }
  std::atomic<long> printed{0};
  std::mutex out_mutex;
  if (o.json) {
    (void)(*sub)->on_pose(".*", [&](const client::TrackedTransform& t) {
      if (o.count > 0 && printed >= o.count) return;
      std::lock_guard lock(out_mutex);
      std::cout << to_json(t).dump() << "\n" << std::flush;
      ++printed;
    });
  }
  const bool tty = ::isatty(STDOUT_FILENO);
  const auto start = std::chrono::steady_clock::now();
  auto next_table = start;
  std::map<std::string, std::pair<long, double>> rates;
  while (!stop_requested()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto now = std::chrono::steady_clock::now();
    if (o.count > 0 && printed >= o.count) break;
    if (o.duration_s > 0 && now - start >= std::chrono::duration<double>(o.duration_s)) break;
    if (!o.json && now >= next_table) {
      next_table = now + std::chrono::milliseconds(tty ? 200 : 1000);
      const std::string t = table(**sub, rates);
      if (tty) std::cout << "\x1b[H\x1b[2J";  // redraw in place
      std::cout << t << (tty ? "" : "\n") << std::flush;
    }
  }
  (*sub)->stop();
  return 0;
}

}  // namespace

void add_echo_command(CLI::App& app) {
  auto o = std::make_shared<EchoOptions>();
  auto* cmd = app.add_subcommand("echo", "show pose streams live (table, or JSON per message)");
  cmd->add_option("pattern", o->subscriber.pattern,
                  "regular expression over device/sensor, whole match (default: all)");
  cmd->add_flag("--json", o->json, "one JSON object per message, one per line");
  cmd->add_option("--lcm-url", o->subscriber.lcm_url, "LCM URL");
  cmd->add_option("--stale", o->subscriber.stale_after_s, "seconds without a message before a stream is stale")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--count", o->count, "exit after this many messages (with --json)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--duration", o->duration_s, "exit after this many seconds")->check(CLI::NonNegativeNumber);
  cmd->callback([o] {
    if (const int rc = run_echo(*o); rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace covtrack::cli
