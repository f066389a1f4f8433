#pragma once
// Draws right perturbations xi ~ N(0, cov) on SE(3): a simulated tracker or emulated unit
// reports T_est = T_true * Exp(-xi), so that T_true = T_est * Exp(xi) has exactly the
// reported covariance (protocol/README.md).
#include <random>

#include "covtrack/protocol/se3.hpp"

namespace covtrack {

class Se3Gaussian {
 public:
  // cov must be symmetric positive semi-definite (a square root via eigen-decomposition
  // handles the singular case, e.g. a sensor with no rotation noise).
  explicit Se3Gaussian(const Mat6& cov);
  Vec6 draw(std::mt19937_64& rng) const;

 private:
  Mat6 sqrt_cov_;
};

}  // namespace covtrack
