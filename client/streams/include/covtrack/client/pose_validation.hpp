#pragma once
// Whether a received pose message may be used (protocol/README.md, "Validity").
#include <optional>
#include <string>

#include <covtrack/pose_cov_t.hpp>

#include "covtrack/client/tracked_transform.hpp"

namespace covtrack::client {

// The reason to reject the message, or nothing. LOST messages skip the covariance
// checks: their covariance is infinite by definition.
std::optional<std::string> rejection_reason(const pose_cov_t& msg);

// The message as a TrackedTransform (call only when rejection_reason() is empty).
TrackedTransform to_tracked_transform(const pose_cov_t& msg, std::int64_t receive_time_us);

}  // namespace covtrack::client
