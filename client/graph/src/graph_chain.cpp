#include "covtrack/client/graph_chain.hpp"

#include <cmath>

namespace covtrack::client {

UncertainPose compose_chain(std::span<const ChainFactor> factors) {
  // Walk from the right end so that the suffix S_k is at hand for every factor.
  Pose suffix = Pose::Identity();
  Mat6 covariance;
  auto it = factors.rbegin();
  // The rightmost factor's perturbation is at the right end already: J = Ad(I) has ones on
  // its diagonal and zeros elsewhere, so J C J^T is C entry for entry (for a finite C;
  // a finite sum says so), and added to the zero start it is C + 0 (a -0 entry comes out
  // +0, as from the products). The usual query (ArView: an object's pose in the camera) is
  // one such factor, and the two 6x6 products were most of its cost.
  if (it != factors.rend() && !it->inverted && std::isfinite(it->covariance.sum())) {
    suffix = it->T * suffix;
    covariance = (it->covariance.array() + 0.0).matrix();
    ++it;
  } else {
    covariance.setZero();
  }
  for (; it != factors.rend(); ++it) {
    Mat6 J;
    if (it->inverted) {
      suffix = it->T.inverse() * suffix;          // the factor is part of its own suffix
      J = se3_adjoint(suffix.inverse());
    } else {
      J = se3_adjoint(suffix.inverse());
      suffix = it->T * suffix;
    }
    covariance += J * it->covariance * J.transpose();
  }
  // Kept exactly symmetric; built in place (a default pose first would be zeroed for nothing).
  return UncertainPose{suffix, 0.5 * (covariance + covariance.transpose()), false};
}

}  // namespace covtrack::client
