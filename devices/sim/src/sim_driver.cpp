#include "covtrack/devices/sim/sim_driver.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <random>

#include <fmt/format.h>

#include "covtrack/protocol/se3_gaussian.hpp"
#include "motion.hpp"

namespace covtrack::sim {
namespace {

// After falling this many periods behind (a stalled machine), ticks are skipped and
// counted as drops instead of being published in a burst with stale times.
constexpr std::uint64_t kMaxBacklogTicks = 10;

class SimDriver final : public Driver {
 public:
  SimDriver(const SimConfig& config, std::uint64_t run_index, DriverClock& clock)
      : config_(config),
        clock_(clock),
        noise_(config.covariance),
        rng_(config.seed + 0x9E3779B97F4A7C15ull * run_index),
        motion_(config.motion, config.seed ^ 0x5151u),
        last_estimate_(config.sensors.size(), Pose::Identity()) {}

  Result<void> run(SampleSink& sink, std::stop_token stop) override {
    using namespace std::chrono;
    const double period_s = 1.0 / config_.rate_hz;
    const auto period = duration_cast<DriverClock::duration>(duration<double>(period_s));
    const auto start = clock_.now();
    const std::int64_t start_us = clock_.now_us();

    for (std::uint64_t tick = 0;; ++tick) {
      if (!clock_.sleep_until(stop, start + tick * period)) return {};
      const auto behind = (clock_.now() - start) / period;
      if (behind > static_cast<std::int64_t>(tick + kMaxBacklogTicks)) {
        for (auto skipped = tick; skipped < static_cast<std::uint64_t>(behind); ++skipped)
          sink.count_drop();
        tick = static_cast<std::uint64_t>(behind);
      }
      const double t = static_cast<double>(tick) * period_s;
      if (config_.inject_failure_every_s > 0 && t >= config_.inject_failure_every_s)
        return fail(fmt::format("injected failure after {} s (inject_failure_every_s)", t));
      report(sink, start_us + std::llround(t * 1e6), motion_.rig_at(t), in_dropout(t));
    }
  }

 private:
  bool in_dropout(double t) const {
    if (config_.dropout_every_s <= 0 || config_.dropout_duration_s <= 0) return false;
    return std::fmod(t, config_.dropout_every_s) >=
           config_.dropout_every_s - config_.dropout_duration_s;
  }

  void report(SampleSink& sink, std::int64_t time_us, const Pose& rig, bool lost) {
    for (std::size_t i = 0; i < config_.sensors.size(); ++i) {
      const Pose T_true = sensor_on_rig(rig, i, config_.motion.sensor_spacing_m);
      const std::string& sensor = config_.sensors[i];
      if (config_.publish_truth)
        sink.truth({sensor, config_.parent_frame, sensor, time_us, T_true});

      PoseSample s{sensor, config_.parent_frame, sensor, time_us};
      if (lost) {
        // LOST carries no information: the last estimate, infinitely uncertain.
        s.status = TrackingStatus::Lost;
        s.T_parent_child = last_estimate_[i];
        s.covariance = lost_covariance();
      } else {
        s.T_parent_child = T_true * se3_exp(-noise_.draw(rng_));
        s.covariance = config_.covariance;
        last_estimate_[i] = s.T_parent_child;
      }
      sink.pose(s);
    }
  }

  SimConfig config_;
  DriverClock& clock_;
  Se3Gaussian noise_;
  std::mt19937_64 rng_;
  Motion motion_;
  std::vector<Pose> last_estimate_;
};

}  // namespace

std::unique_ptr<Driver> make_sim_driver(const SimConfig& config, std::uint64_t run_index, DriverClock& clock) {
  return std::make_unique<SimDriver>(config, run_index, clock);
}

}  // namespace covtrack::sim
