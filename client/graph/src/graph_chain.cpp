#include "covtrack/client/graph_chain.hpp"

namespace covtrack::client {

UncertainPose compose_chain(std::span<const ChainFactor> factors) {
  // Walk from the right end so that the suffix S_k is at hand for every factor.
  Pose suffix = Pose::Identity();
  Mat6 covariance = Mat6::Zero();
  for (auto it = factors.rbegin(); it != factors.rend(); ++it) {
    // The rightmost factor's perturbation is at the right end already: J = Ad(I) has ones
    // on its diagonal and zeros elsewhere, so J C J^T is C entry for entry (a finite C;
    // zeros come out +0 either way, the sum starting from +0). The usual query (ArView: an
    // object's pose in the camera) is one such factor, and the two 6x6 products were most
    // of its cost.
    if (it == factors.rbegin() && !it->inverted && it->covariance.allFinite()) {
      suffix = it->T * suffix;
      covariance += it->covariance;
      continue;
    }
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
  UncertainPose out;
  out.T = suffix;
  out.covariance = 0.5 * (covariance + covariance.transpose());  // keep it exactly symmetric
  return out;
}

}  // namespace covtrack::client
