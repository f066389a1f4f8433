#include "motion.hpp"

#include <cmath>
#include <numbers>

namespace covtrack::sim {
namespace {
// A pose at p whose x axis points along the horizontal direction of travel.
Pose facing(const Vec3& p, const Vec3& velocity) {
  Pose T = Pose::Identity();
  T.translation() = p;
  const double yaw = std::atan2(velocity.y(), velocity.x());
  T.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  return T;
}
}  // namespace

Motion::Motion(const MotionConfig& config, std::uint64_t seed) : config_(config), rng_(seed) {
  walk_.translation() = config_.center_m;
}

Pose Motion::rig_at(double t) {
  const double w = 2 * std::numbers::pi / config_.period_s;
  const double r = config_.radius_m;
  const Vec3& c = config_.center_m;
  switch (config_.kind) {
    case MotionKind::Static: {
      Pose T = Pose::Identity();
      T.translation() = c;
      return T;
    }
    case MotionKind::Circle:
      return facing(c + r * Vec3(std::cos(w * t), std::sin(w * t), 0),
                    Vec3(-std::sin(w * t), std::cos(w * t), 0));
    case MotionKind::FigureEight:  // a Lissajous curve 1:2
      return facing(c + r * Vec3(std::sin(w * t), 0.5 * std::sin(2 * w * t), 0),
                    Vec3(std::cos(w * t), std::cos(2 * w * t), 0));
    case MotionKind::RandomWalk: return random_walk_step(t);
    case MotionKind::Waypoints: return along_waypoints(t);
  }
  return Pose::Identity();
}

Pose Motion::random_walk_step(double t) {
  const double dt = t - walk_t_s_;
  walk_t_s_ = t;
  if (dt <= 0) return walk_;
  std::normal_distribution<double> n(0.0, 1.0);
  const double sp = config_.walk_sigma_m * std::sqrt(dt);
  const double sr = config_.walk_sigma_rad * std::sqrt(dt);
  Vec3 p = walk_.translation() + sp * Vec3(n(rng_), n(rng_), n(rng_));
  // Reflect into the box of half width radius_m around the centre, so it never wanders off.
  for (int i = 0; i < 3; ++i) {
    const double lo = config_.center_m(i) - config_.radius_m;
    const double hi = config_.center_m(i) + config_.radius_m;
    if (p(i) > hi) p(i) = 2 * hi - p(i);
    if (p(i) < lo) p(i) = 2 * lo - p(i);
  }
  walk_.linear() = walk_.linear() * so3_exp(sr * Vec3(n(rng_), n(rng_), n(rng_)));
  walk_.translation() = p;
  return walk_;
}

Pose Motion::along_waypoints(double t) const {
  const auto& pts = config_.waypoints_m;
  double lap = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) lap += (pts[(i + 1) % pts.size()] - pts[i]).norm();
  if (lap <= 0) return facing(pts.front(), Vec3::UnitX());
  double s = std::fmod(config_.speed_mps * t, lap);
  for (std::size_t i = 0;; i = (i + 1) % pts.size()) {
    const Vec3 seg = pts[(i + 1) % pts.size()] - pts[i];
    const double len = seg.norm();
    if (s <= len && len > 0) return facing(pts[i] + seg * (s / len), seg);
    s -= len;
  }
}

Pose sensor_on_rig(const Pose& rig, std::size_t index, double spacing_m) {
  Pose offset = Pose::Identity();
  offset.translation() = Vec3(0, static_cast<double>(index) * spacing_m, 0);
  return rig * offset;
}

}  // namespace covtrack::sim
