#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include <fmt/format.h>

#include "covariance_model.hpp"
#include "covtrack/devices/serial/serial_port.hpp"
#include "device_session.hpp"

namespace covtrack::serial6dof {
namespace {

using Clock = DriverClock;

// With every station silent this long (and at least this many watchdog periods), the
// unit is considered stuck and the driver fails so that the restart resets it.
constexpr double kStuckAfter_s = 1.0;
constexpr double kStuckAfterWatchdogs = 10;

struct StationState {
  MotionGate gate;
  Clock::time_point last_record;
  Clock::time_point last_lost_report;
  bool lost = false;
  Pose last_estimate = Pose::Identity();
};

std::unique_ptr<DeviceSession> make_session(const Serial6dofConfig& c) {
  switch (protocol_of(c.model)) {
    case Protocol::Fastrak: return make_fastrak_session(c);
    case Protocol::Liberty: return make_liberty_session(c);
    case Protocol::Flock: return make_flock_session(c);
  }
  return nullptr;
}

double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

class Serial6dofDriver final : public Driver {
 public:
  Serial6dofDriver(const Serial6dofConfig& config, std::uint64_t run_index, DriverClock& clock)
      : config_(config), spec_(model_spec(config.model)), run_index_(run_index), clock_(clock),
        stations_(config.stations.size(), StationState{MotionGate(config.motion, config.period_s())}) {}

  Result<void> run(SampleSink& sink, std::stop_token stop) override {
    auto port = serial::SerialPort::open({.path = config_.port, .baud = config_.baud});
    if (!port) return fail(port.error().message);
    DeviceLink link(**port, sink, config_.publish_raw, stop, clock_);
    auto session = make_session(config_);
    const bool reset = config_.reset_on_start || run_index_ > 0;
    if (auto r = session->start(link, reset); !r) return r;
    if (stop.stop_requested()) return {};
    return stream(link, *session, sink);
  }

 private:
  Result<void> stream(DeviceLink& link, DeviceSession& session, SampleSink& sink) {
    using namespace std::chrono;
    const auto started = clock_.now();
    for (auto& s : stations_) s.last_record = s.last_lost_report = started;
    // Wake often enough to see a silent station within its watchdog time.
    const auto poll = milliseconds(std::clamp<long>(std::lround(config_.watchdog_s() * 250), 1, 20));
    const double stuck_after_s = std::max(kStuckAfter_s, kStuckAfterWatchdogs * config_.watchdog_s());
    std::vector<std::uint8_t> bytes;
    std::uint64_t resyncs = 0, bad = 0;

    while (!link.stopped()) {
      bytes.clear();
      auto n = link.read(bytes, poll);
      if (!n) {
        report_all_lost(sink);
        return fail(fmt::format("{} (stations reported LOST)", n.error().message));
      }
      const auto now = clock_.now();
      const std::int64_t time_us = clock_.now_us() - std::llround(config_.latency_s * 1e6);
      const auto items = session.feed(bytes);
      // Records that arrive together were measured one report period apart, the last
      // one just now: a shared receive time would misplace all but the last (and a
      // moving receiver's prediction with them).
      std::map<int, int> left;  // station -> records still to come in this read
      for (const auto& item : items)
        if (const auto* record = std::get_if<TrackerRecord>(&item)) ++left[record->station];
      for (const auto& item : items)
        if (const auto* record = std::get_if<TrackerRecord>(&item))
          report(sink, *record, now, time_us - std::llround(--left[record->station] * config_.period_s() * 1e6));
      for (; resyncs < session.resyncs(); ++resyncs) sink.count_resync();
      if (session.bad_records() > bad) {
        bad = session.bad_records();
        sink.count_error(fmt::format("{}: {}", config_.port, session.last_problem()));
      }
      if (watchdog(sink, now) > stuck_after_s)
        return fail(fmt::format("{}: no records for {:.1f} s; the unit will be reset", config_.port,
                                stuck_after_s));
    }
    return {};
  }

  void report(SampleSink& sink, const TrackerRecord& record, Clock::time_point now,
              std::int64_t time_us) {
    const auto it = std::find_if(config_.stations.begin(), config_.stations.end(),
                                 [&](const StationConfig& s) { return s.number == record.station; });
    if (it == config_.stations.end()) {
      sink.count_error(fmt::format("{}: record for station {}, which is not configured",
                                   config_.port, record.station));
      return;
    }
    const auto i = static_cast<std::size_t>(it - config_.stations.begin());
    const auto u = record_uncertainty(record, spec_, it->covariance, config_.trouble_inflation);
    PoseSample s{it->name, config_.parent_frame, it->name, time_us};
    s.T_parent_child = pose_from(record.position_m, record.orientation);
    const auto verdict = stations_[i].gate.check(s.T_parent_child, u.covariance, u.status, time_us * 1e-6);
    if (verdict.kind == GateVerdict::Kind::Reject) {
      sink.count_error(fmt::format("{}: station {}: record dropped: {}", config_.port, record.station,
                                   verdict.reason));
      return;
    }
    stations_[i].last_record = now;
    if (verdict.kind == GateVerdict::Kind::Hold) return;  // published once the next agrees
    s.covariance = verdict.covariance;
    s.status = verdict.status;
    stations_[i].lost = false;
    stations_[i].last_estimate = s.T_parent_child;
    sink.pose(s);
  }

  // Reports silent stations LOST (once per report period while silent); returns how
  // long the most recently heard station has been silent.
  double watchdog(SampleSink& sink, Clock::time_point now) {
    double least_silent_s = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < stations_.size(); ++i) {
      auto& s = stations_[i];
      const double silent_s = seconds_between(s.last_record, now);
      least_silent_s = std::min(least_silent_s, silent_s);
      if (silent_s < config_.watchdog_s()) continue;
      if (s.lost && seconds_between(s.last_lost_report, now) < config_.period_s()) continue;
      report_lost(sink, i, now);
    }
    return least_silent_s;
  }

  void report_all_lost(SampleSink& sink) {
    for (std::size_t i = 0; i < stations_.size(); ++i) report_lost(sink, i, clock_.now());
  }

  void report_lost(SampleSink& sink, std::size_t i, Clock::time_point now) {
    const auto& st = config_.stations[i];
    PoseSample s{st.name, config_.parent_frame, st.name, clock_.now_us()};
    s.status = TrackingStatus::Lost;  // LOST carries no information: infinite covariance
    s.T_parent_child = stations_[i].last_estimate;
    s.covariance = lost_covariance();
    stations_[i].lost = true;
    stations_[i].last_lost_report = now;  // the gate restarts by itself after a long silence
    sink.pose(s);
  }

  Serial6dofConfig config_;
  const ModelSpec& spec_;
  std::uint64_t run_index_;
  DriverClock& clock_;
  std::vector<StationState> stations_;
};

}  // namespace

std::unique_ptr<Driver> make_serial6dof_driver(const Serial6dofConfig& config, std::uint64_t run_index,
                                               DriverClock& clock) {
  return std::make_unique<Serial6dofDriver>(config, run_index, clock);
}

}  // namespace covtrack::serial6dof
