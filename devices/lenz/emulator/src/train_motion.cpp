#include "covtrack/emulators/lenz/train_motion.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fmt/format.h>

namespace covtrack::lenz {

Result<std::vector<SpeedStep>> parse_speed_profile(const std::string& text) {
  std::vector<SpeedStep> steps;
  std::stringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    SpeedStep step;
    char colon = 0;
    std::istringstream in(item);
    if (!(in >> step.speed_mps >> colon >> step.hold_s) || colon != ':' || !in.eof() || step.hold_s < 0 ||
        !std::isfinite(step.speed_mps) || !std::isfinite(step.hold_s))
      return fail(fmt::format("speed profile item '{}': expected speed_mps:hold_s (speed < 0: backwards, "
                              "hold >= 0)", item));
    steps.push_back(step);
  }
  if (steps.empty()) return fail("speed profile is empty");
  return steps;
}

TrainMotion::TrainMotion(std::vector<SpeedStep> profile, double accel_mps2, double start_s) : start_s_(start_s) {
  if (profile.empty() || profile.back().speed_mps != 0) profile.push_back({0, 0});
  double t = 0, s = 0, v = 0;
  const auto add = [&](double accel, double duration) {
    if (duration <= 0) return;
    phases_.push_back({t, s, v, accel, duration});
    s += v * duration + accel * duration * duration / 2;
    v += accel * duration;
    t += duration;
  };
  for (const auto& step : profile) {
    const double dv = step.speed_mps - v;
    add(dv > 0 ? accel_mps2 : -accel_mps2, std::abs(dv) / accel_mps2);
    v = step.speed_mps;  // exactly, despite rounding
    add(0, step.hold_s);
  }
  if (phases_.empty()) phases_.push_back({0, 0, 0, 0, 1});  // a profile of standing still
  cycle_s_ = t > 0 ? t : 1;
  cycle_m_ = s;
}

const TrainMotion::Phase& TrainMotion::phase_at(double tc) const {
  auto it = std::upper_bound(phases_.begin(), phases_.end(), tc, [](double v, const Phase& p) { return v < p.t0; });
  return *std::prev(it == phases_.begin() ? std::next(it) : it);
}

double TrainMotion::s_at(double t) const {
  t = std::max(t, 0.0);
  const double cycles = std::floor(t / cycle_s_);
  const double tc = t - cycles * cycle_s_;
  const Phase& p = phase_at(tc);
  const double dt = std::min(tc - p.t0, p.duration);
  return start_s_ + cycles * cycle_m_ + p.s0 + p.v0 * dt + p.accel * dt * dt / 2;
}

double TrainMotion::speed_at(double t) const {
  t = std::max(t, 0.0);
  const double tc = t - std::floor(t / cycle_s_) * cycle_s_;
  const Phase& p = phase_at(tc);
  return p.v0 + p.accel * std::min(tc - p.t0, p.duration);
}

}  // namespace covtrack::lenz
