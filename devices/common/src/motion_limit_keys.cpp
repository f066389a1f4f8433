#include "covtrack/devices/motion_limit_keys.hpp"

namespace covtrack {

std::vector<KeySpec> motion_limit_keys() {
  static const MotionLimits d;
  static const std::string speed = std::to_string(static_cast<int>(d.max_speed_mps)),
                           accel = std::to_string(static_cast<int>(d.max_accel_mps2)),
                           rate = std::to_string(static_cast<int>(d.max_angular_rate_radps)),
                           angular_accel = std::to_string(static_cast<int>(d.max_angular_accel_radps2));
  return {
      {"gate", ValueType::Boolean, "", "true",
       "test each record against what the sensor can physically do and against a short "
       "constant-velocity prediction: impossible records are dropped (counted as errors), "
       "surprising ones published DEGRADED with a widened covariance"},
      {"max_speed_mps", ValueType::Float, "m/s", speed, "fastest the tracked thing moves", 0.01, 1000},
      {"max_accel_mps2", ValueType::Float, "m/s^2", accel, "hardest it accelerates", 0.1, 1e5},
      {"max_angular_rate_radps", ValueType::Float, "rad/s", rate, "fastest it turns", 0.01, 1000},
      {"max_angular_accel_radps2", ValueType::Float, "rad/s^2", angular_accel,
       "hardest its turning accelerates", 0.1, 1e6},
  };
}

MotionLimits read_motion_limits(TableReader& r) {
  MotionLimits m;
  m.enabled = r.boolean("gate", m.enabled);
  m.max_speed_mps = r.number("max_speed_mps", m.max_speed_mps);
  m.max_accel_mps2 = r.number("max_accel_mps2", m.max_accel_mps2);
  m.max_angular_rate_radps = r.number("max_angular_rate_radps", m.max_angular_rate_radps);
  m.max_angular_accel_radps2 = r.number("max_angular_accel_radps2", m.max_angular_accel_radps2);
  return m;
}

}  // namespace covtrack
