#pragma once
// A pose with its 6x6 covariance in the canonical BODY convention (protocol/README.md):
// T_true = T * Exp(xi), xi ~ N(0, covariance), tangent [translation, rotation].
#include "covtrack/protocol/se3.hpp"

namespace covtrack::client {

struct UncertainPose {
  Pose T = Pose::Identity();
  Mat6 covariance = Mat6::Zero();
  // Infinitely uncertain (a LOST edge on the path): covariance is meaningless.
  bool unbounded = false;
};

}  // namespace covtrack::client
