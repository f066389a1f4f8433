#pragma once
// Plausibility of a decoded pose: a record that framed correctly but carries non-finite
// numbers or a quaternion far from unit length is corrupt, not a pose.
#include <cmath>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "tracker_record.hpp"

namespace covtrack::serial6dof {

// Quantised quaternions (Flock: 14 bits) and float rounding stay far inside this.
constexpr double kQuaternionNormTolerance = 0.02;
// No tracker of this family reaches further than this from its source.
constexpr double kMaxRange_m = 100;

inline std::optional<std::string> record_problem(const TrackerRecord& r) {
  const auto& q = r.orientation;
  if (!r.position_m.allFinite() || !q.coeffs().allFinite() ||
      (r.device_time_s && !std::isfinite(*r.device_time_s)))  // a float timestamp can be NaN too
    return fmt::format("station {}: non-finite number in record", r.station);
  if (std::abs(q.norm() - 1.0) > kQuaternionNormTolerance)
    return fmt::format("station {}: quaternion norm {:.4f} is not 1", r.station, q.norm());
  if (r.position_m.norm() > kMaxRange_m)
    return fmt::format("station {}: position {:.1f} m from the source is implausible", r.station,
                       r.position_m.norm());
  return std::nullopt;
}

}  // namespace covtrack::serial6dof
