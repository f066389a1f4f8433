#include "covtrack/client/graph_chain.hpp"

namespace covtrack::client {

UncertainPose compose_chain(std::span<const ChainFactor> factors) {
  // Walk from the right end so that the suffix S_k is at hand for every factor.
  Pose suffix = Pose::Identity();
  Mat6 covariance = Mat6::Zero();
  for (auto it = factors.rbegin(); it != factors.rend(); ++it) {
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
