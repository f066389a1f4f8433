#pragma once
// First-order uncertainty of a product of independent uncertain poses on SE(3).
//
// Convention (protocol/README.md): every covariance is BODY, T_true = T * Exp(xi).
// For T = F_1 * F_2 * ... * F_n, a perturbation of factor k moves to the right end:
//   F_k Exp(x) S_k = F_k S_k Exp(Ad(S_k^-1) x),   S_k = F_{k+1} ... F_n,
// so cov(T) = sum_k Ad(S_k^-1) C_k Ad(S_k^-1)^T (the factors are independent).
// An inverted factor inv(E Exp(x)) = Exp(-x) inv(E) has its perturbation on its left;
// moved to the right end it gives Ad((inv(E) S_k)^-1) = Ad(S_k^-1 E): the sign of x
// does not change the covariance.
#include <span>

#include "covtrack/client/uncertain_pose.hpp"

namespace covtrack::client {

struct ChainFactor {
  Pose T = Pose::Identity();        // the edge's value T_parent_child
  Mat6 covariance = Mat6::Zero();   // BODY covariance of T (not of its inverse)
  bool inverted = false;            // the chain uses inv(T) (walking up the tree)
};

// The product of the factors in order, with its BODY covariance (pure maths: LOST edges
// are the caller's business and must not reach this function).
UncertainPose compose_chain(std::span<const ChainFactor> factors);

}  // namespace covtrack::client
