#include "covtrack/client/level_of_error.hpp"

#include <cmath>
#include <string>

namespace covtrack::client {

Result<LevelOfError> LevelOfError::create(std::vector<double> thresholds, double margin) {
  if (!std::isfinite(margin) || margin < 0)
    return fail("level of error: margin must be finite and >= 0, got " + std::to_string(margin));
  for (std::size_t i = 0; i < thresholds.size(); ++i) {
    if (!std::isfinite(thresholds[i]))
      return fail("level of error: threshold " + std::to_string(i) + " is not finite");
    if (i > 0 && !(thresholds[i] > thresholds[i - 1]))
      return fail("level of error: threshold " + std::to_string(i) + " (" +
                  std::to_string(thresholds[i]) + ") is not above threshold " +
                  std::to_string(i - 1) + " (" + std::to_string(thresholds[i - 1]) + ")");
  }
  return LevelOfError(std::move(thresholds), margin);
}

int LevelOfError::update(double assessment) {
  const int last = static_cast<int>(thresholds_.size());
  if (std::isnan(assessment)) return level_ = last;
  int reached = 0;  // highest level whose threshold is met without any margin
  while (reached < last && assessment >= thresholds_[static_cast<std::size_t>(reached)]) ++reached;
  if (reached > level_) return level_ = reached;
  while (level_ > 0 && assessment < thresholds_[static_cast<std::size_t>(level_ - 1)] - margin_)
    --level_;
  return level_;
}

}  // namespace covtrack::client
