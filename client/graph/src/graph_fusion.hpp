#pragma once
// Fusion of several estimates of one relation that reach it along different paths of the
// transform graph (TransformGraph::add_fused_frame).
//
// Two paths that share an edge are correlated through it, and the graph knows exactly how:
// its edges are independent, so to first order every estimate is a linear function of the
// edges' own perturbations,
//     xi = sum over edges e of J_e xi_e,   xi_e ~ N(0, C_e), independent,
// and the cross-covariance of two estimates is the sum over their SHARED edges of
// J_e C_e J'_e^T. With the joint covariance R of the estimates (each moved into the tangent
// space at a common base pose), the best linear unbiased fusion is generalised least
// squares:
//     P = (H^T R^-1 H)^-1,   x = P H^T R^-1 z,   H = [I; I; ...],   z = stacked offsets.
// Independent paths give the familiar information sum; a shared edge is counted once.
// The fused estimate is again linear in the edges (its sensitivities are the gain times
// the paths'), so it can itself be a step of a longer path or of another fusion, and its
// correlation with the rest of a query stays exact.
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "covtrack/client/uncertain_pose.hpp"

namespace covtrack::client::fusion {

using EdgeKey = std::size_t;  // the graph's index of the edge's child frame

// d(estimate) = J d(edge): the BODY perturbation of the estimate caused by the edge's.
struct Sensitivity {
  EdgeKey edge = 0;
  Mat6 J = Mat6::Identity();
};

struct LinearEstimate {
  Pose T = Pose::Identity();
  std::vector<Sensitivity> terms;  // at most one per edge
};

// The covariance of an edge's own perturbation.
using EdgeCovariance = std::function<const Mat6&(EdgeKey)>;

// One step of a product: the estimate used as it is, or inverted.
struct LinearFactor {
  const LinearEstimate* estimate = nullptr;
  bool inverted = false;
};

// The product of the factors in order, with the sensitivities moved to its right end
// (graph_chain.hpp derives the Jacobians; an inverted factor also flips the sign, which a
// covariance does not see but a cross-covariance does).
LinearEstimate compose(std::span<const LinearFactor> factors);

// Sum over edges of J_a C J_b^T, for the edges both estimates depend on.
Mat6 cross_covariance(const LinearEstimate& a, const LinearEstimate& b, const EdgeCovariance& C);
inline Mat6 covariance(const LinearEstimate& a, const EdgeCovariance& C) {
  return cross_covariance(a, a, C);
}

// The generalised least-squares fusion above, linearised at the estimate with the
// smallest covariance trace (its index goes to *base_out). At least one estimate.
LinearEstimate fuse(std::span<const LinearEstimate> estimates, const EdgeCovariance& C,
                    std::size_t* base_out = nullptr);

}  // namespace covtrack::client::fusion
