#pragma once
// Level of Error switch (dissertation 5.6.2, docs/background.md): the application gives
// several augmentations of the same object, from the one for the smallest error (drawn over
// the object) to the one for the largest (clues only), and thresholds on the object's
// assessment between them. The switch picks the augmentation for the current assessment,
// with hysteresis so an assessment that hovers at a threshold does not make the view
// flicker:
//  - up:   to level k as soon as assessment >= thresholds[k-1];
//  - down: from level k only once assessment < thresholds[k-1] - margin.
// An unbounded (+inf) or unknown (NaN) assessment selects the last level: with no bound
// on the error, only the augmentation that does not rely on registration is honest.
#include <span>
#include <vector>

#include "covtrack/protocol/result.hpp"

namespace covtrack::client {

class LevelOfError {
 public:
  // `thresholds`: finite, strictly ascending (n thresholds -> n + 1 levels);
  // `margin`: finite, >= 0, in the assessment's unit (e.g. px). Errors say which value.
  static Result<LevelOfError> create(std::vector<double> thresholds, double margin);

  // Feeds one assessment; returns the level now chosen, 0 ... level_count() - 1.
  int update(double assessment);

  // Level 0 until the first update.
  int level() const { return level_; }
  int level_count() const { return static_cast<int>(thresholds_.size()) + 1; }

  // The augmentation for the current level, given one per level.
  template <typename T>
  const T& choose(std::span<const T> augmentations) const {
    return augmentations[static_cast<std::size_t>(level_)];
  }

 private:
  LevelOfError(std::vector<double> thresholds, double margin)
      : thresholds_(std::move(thresholds)), margin_(margin) {}

  std::vector<double> thresholds_;
  double margin_ = 0;
  int level_ = 0;
};

}  // namespace covtrack::client
