#include "hydra_stream.hpp"

#include <limits>

#include <fmt/format.h>

namespace covtrack::hydra {

HydraStream::HydraStream(const HydraConfig& config)
    : config_(config),
      gates_{MotionGate(config.motion, 1.0 / config.rate_hz), MotionGate(config.motion, 1.0 / config.rate_hz)} {}

HydraStream::Out HydraStream::on_report(const HydraReport& report, std::int64_t time_us) {
  Out out;
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& c = report.controllers[i];
    PoseSample s{config_.sensors[i], config_.parent_frame, config_.sensors[i], time_us};
    s.T_parent_child = pose_from(hemisphere_.resolve(static_cast<int>(i), c.position_m), c.orientation);
    const auto verdict = gates_[i].check(s.T_parent_child, config_.covariance, TrackingStatus::Ok,
                                         static_cast<double>(time_us) * 1e-6);
    if (verdict.kind == GateVerdict::Kind::Reject) {
      out.errors.push_back(fmt::format("Razer Hydra: {}: pose dropped: {}", config_.sensors[i], verdict.reason));
      continue;
    }
    if (verdict.kind == GateVerdict::Kind::Hold) continue;  // published once the next agrees
    s.covariance = verdict.covariance;
    s.status = verdict.status;
    last_[i] = s.T_parent_child;
    out.samples.push_back(s);
  }
  return out;
}

std::vector<PoseSample> HydraStream::lost(std::int64_t time_us) {
  std::vector<PoseSample> out;
  for (std::size_t i = 0; i < 2; ++i) {
    PoseSample s{config_.sensors[i], config_.parent_frame, config_.sensors[i], time_us};
    s.status = TrackingStatus::Lost;  // LOST carries no information: infinite covariance
    s.T_parent_child = last_[i];
    s.covariance = lost_covariance();
    gates_[i].restart();
    out.push_back(s);
  }
  return out;
}

}  // namespace covtrack::hydra
