#include "covtrack/emulators/serial6dof/emulator.hpp"

#include <chrono>
#include <numbers>
#include <random>

#include "covariance_model.hpp"
#include "covtrack/devices/serial/pseudo_terminal.hpp"
#include "covtrack/protocol/se3_gaussian.hpp"
#include "emulated_unit.hpp"
#include "line_noise.hpp"
#include "sway.hpp"

namespace covtrack::emulate6dof {

using namespace std::chrono;
using namespace serial6dof;
using Clock = DriverClock;

std::vector<EmulatedStation> default_stations(const std::vector<int>& numbers) {
  std::vector<EmulatedStation> out;
  for (std::size_t i = 0; i < numbers.size(); ++i) {
    const double k = static_cast<double>(i);
    EmulatedStation s;
    s.number = numbers[i];
    s.name = "st" + std::to_string(numbers[i]);
    // Within 0.5 m of the source, where the specified accuracy holds.
    s.T_source_receiver = pose_from(
        Vec3(0.30, -0.15 + 0.1 * k, 0.10),
        Eigen::Quaterniond(Eigen::AngleAxisd(0.3 + 0.4 * k, Vec3(0.2, 0.5 + 0.1 * k, 1).normalized())));
    out.push_back(s);
  }
  return out;
}

class Emulator::Impl {
 public:
  Impl(const EmulatorConfig& c, serial::PseudoTerminal pty, DriverClock& clock)
      : config_(c), spec_(model_spec(c.model)), clock_(clock), pty_(std::move(pty)), rng_(c.seed),
        noise_rng_(c.seed ^ 0x6e6f697365ull),
        noise_{c.bit_flips_per_s, c.bytes_dropped_per_s, c.bytes_duplicated_per_s} {
    if (config_.rate_hz <= 0)
      config_.rate_hz = station_rate_hz(spec_, static_cast<int>(config_.stations.size()));
    if (config_.reset_time_s < 0) config_.reset_time_s = spec_.reset_time_s;
    switch (spec_.protocol) {
      case Protocol::Fastrak: unit_ = make_fastrak_unit(config_); break;
      case Protocol::Liberty: unit_ = make_liberty_unit(config_); break;
      case Protocol::Flock: unit_ = make_flock_unit(config_); break;
    }
  }

  void run(Emulator& e, std::stop_token stop, const TruthCallback& on_truth) {
    const auto period = duration_cast<Clock::duration>(duration<double>(1.0 / config_.rate_hz));
    auto next_report = clock_.now() + period;
    auto reset_done = Clock::time_point::min();
    auto next_trouble = clock_.now() + duration_cast<Clock::duration>(duration<double>(config_.trouble_every_s));
    std::vector<std::uint8_t> input;
    Bytes reply;

    while (!stop.stop_requested()) {
      if (!follow_plug(e)) {
        clock_.sleep_until(stop, clock_.now() + milliseconds(5));
        continue;
      }
      const auto now = clock_.now();
      const bool resetting = now < reset_done;
      e.resetting_ = resetting;
      std::uint8_t buffer[1024];
      auto n = pty_.read_some(buffer, clock_.io_timeout(stop, next_report, milliseconds(5)));
      if (n && *n && !resetting) {  // a resetting unit does not listen
        input.insert(input.end(), buffer, buffer + *n);
        reply.clear();
        if (unit_->handle(input, reply)) {
          input.clear();
          unit_->power_on();
          e.hung_ = false;
          reset_done = clock_.now() + duration_cast<Clock::duration>(duration<double>(config_.reset_time_s));
          ++e.resets_;
        }
        if (!reply.empty()) (void)pty_.write(reply);
      }
      if (clock_.now() < next_report) continue;
      const auto sampled = next_report;  // a real unit samples on its own clock, late or not
      next_report += period;
      if (clock_.now() > next_report + 10 * period) next_report = clock_.now() + period;  // stalled
      if (resetting || e.hung_ || !unit_->streaming()) continue;
      bool trouble = false;
      if (config_.trouble_every_s > 0 && unit_->trouble_code() >= 0 && clock_.now() >= next_trouble) {
        trouble = true;
        next_trouble += duration_cast<Clock::duration>(duration<double>(config_.trouble_every_s));
      }
      report(e, trouble, on_truth, sampled);
    }
  }

 private:
  // Applies unplug/replug requests; false while unplugged.
  bool follow_plug(Emulator& e) {
    if (e.want_plugged_ != pty_.plugged()) {
      if (e.want_plugged_) {
        if (pty_.replug()) unit_->power_on();  // a replugged unit starts from power-up
        e.plugged_ = pty_.plugged();
      } else {
        // Cleared before the hang-up: a test that sees the driver fail and then waits for
        // plugged() after replug() must not see this stale "plugged" and race the new link.
        e.plugged_ = false;
        pty_.unplug();
      }
    }
    return pty_.plugged();
  }

  void report(Emulator& e, bool trouble, const TruthCallback& on_truth, Clock::time_point sampled) {
    const std::int64_t time_us = clock_.now_us() - duration_cast<microseconds>(clock_.now() - sampled).count();
    const double t_s = duration<double>(sampled - started_).count();
    std::vector<TrackerRecord> records;
    for (std::size_t i = 0; i < config_.stations.size(); ++i) {
      const auto& st = config_.stations[i];
      const Pose T_true = st.T_source_receiver * sway(t_s, i, config_.sway_m, config_.sway_rad, config_.sway_hz);
      TrackerRecord truth;
      truth.station = st.number;
      truth.position_m = T_true.translation();
      truth.orientation = Eigen::Quaterniond(T_true.linear());
      truth.status_code = trouble ? unit_->trouble_code() : (spec_.protocol == Protocol::Fastrak ? ' ' : 0);
      truth.trouble = trouble;
      truth.device_time_s = static_cast<double>(time_us % 1000000000) * 1e-6;
      // The noise the driver will claim for this record (same model, same inflation).
      const auto u = record_uncertainty(truth, spec_, std::nullopt, config_.trouble_inflation);
      const Pose T_est = T_true * se3_exp(-Se3Gaussian(u.covariance).draw(rng_));
      TrackerRecord r = truth;
      r.position_m = T_est.translation();
      r.orientation = Eigen::Quaterniond(T_est.linear());
      if (r.orientation.w() < 0) r.orientation.coeffs() = -r.orientation.coeffs();
      records.push_back(r);
      if (on_truth)
        on_truth({st.name, config_.parent_frame, st.name, time_us, T_true});
    }
    Bytes bytes = unit_->encode(records);
    if (noise_.any()) {
      // The first record after configuration gets one period's worth, not the whole reset's.
      const double elapsed_s = std::min(t_s - last_sent_s_, 2.0 / config_.rate_hz);
      e.noise_events_ += apply_line_noise(bytes, elapsed_s, noise_, noise_rng_);
      last_sent_s_ = t_s;
    }
    if (!bytes.empty() && pty_.write(bytes)) e.records_sent_ += records.size();
  }

  EmulatorConfig config_;
  const ModelSpec& spec_;
  DriverClock& clock_;
  serial::PseudoTerminal pty_;
  std::unique_ptr<EmulatedUnit> unit_;
  std::mt19937_64 rng_;
  std::mt19937_64 noise_rng_;  // apart from rng_: the same seed gives the same pose noise
  LineNoiseRates noise_;
  Clock::time_point started_ = clock_.now();
  double last_sent_s_ = 0;
};

Result<std::unique_ptr<Emulator>> Emulator::create(const EmulatorConfig& config, DriverClock& clock) {
  if (config.stations.empty()) return fail("emulator: no stations configured");
  auto pty = serial::PseudoTerminal::create(config.link_path);
  if (!pty) return fail("emulator: " + pty.error().message);
  const std::string path = pty->device_path();
  auto e = std::unique_ptr<Emulator>(new Emulator(std::make_unique<Impl>(config, std::move(*pty), clock)));
  e->device_path_ = path;
  return e;
}

Emulator::Emulator(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Emulator::~Emulator() { stop(); }

void Emulator::start(TruthCallback on_truth) {
  thread_ = std::jthread([this, on_truth = std::move(on_truth)](std::stop_token stop) {
    impl_->run(*this, stop, on_truth);
  });
}

void Emulator::stop() {
  thread_.request_stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace covtrack::emulate6dof
