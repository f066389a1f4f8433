#pragma once
// Chooses or fuses several estimates of the same transform (the dissertation's
// TransformCombiner, section 4.4; docs/background.md): e.g. a marker tracker seen by the
// camera and a room tracker that both give T_world_object.
//
// Rules common to every policy:
// - an unbounded (LOST) candidate is never chosen while another one is bounded; the
//   policy (including a user callback) only ever sees the bounded candidates;
// - if every candidate is unbounded, the result is unbounded and `chosen` is the first;
// - the caller always learns which input was used (`chosen`) and whether it was fused.
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "covtrack/client/uncertain_pose.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::client {

struct Combined {
  UncertainPose pose;
  std::size_t chosen = 0;  // index into the candidates; for a fusion, the linearisation base
  bool fused = false;      // pose is a fusion of several candidates, not one of them
};

// How "small" a covariance is for the smallest-covariance policy.
enum class CovarianceSize {
  TranslationTrace,        // trace of the 3x3 translation block (m^2): what registration
                           // error mostly depends on, and no mixing of m^2 with rad^2
  TranslationDeterminant,  // determinant of that block: volume of the position ellipsoid
};

class Combiner {
 public:
  // Receives the bounded candidates only and returns one of them (its index in the span
  // it received) or a fusion of them.
  using Callback = std::function<Combined(std::span<const UncertainPose> bounded)>;

  // The dissertation's SmallestCovarianceCombiner: the estimate with the smallest
  // covariance.
  static Combiner smallest(CovarianceSize size = CovarianceSize::TranslationTrace);
  // Covariance intersection (Julier & Uhlmann): consistent whatever the (unknown)
  // correlation between the candidates. Fuses the bounded candidates one after another.
  static Combiner covariance_intersection();
  static Combiner callback(Callback callback);

  // Fails on an empty candidate list or when a callback returns an index out of range.
  Result<Combined> combine(std::span<const UncertainPose> candidates) const;

 private:
  explicit Combiner(Callback policy) : policy_(std::move(policy)) {}
  Callback policy_;
};

// One covariance intersection of two estimates of the same pose, in the tangent space at
// `a`: b is moved there (b (-) a, its covariance through the inverse right Jacobian) and
//   P^-1 = w Pa^-1 + (1 - w) Pb^-1,  x = P (1 - w) Pb^-1 (b (-) a),
// with w in [0, 1] minimising trace(P) (golden-section search; the trace mixes m^2 and
// rad^2, as standard CI does: scale your units if that matters). The result is a (+) x with
// P carried to the tangent at the new mean by the right Jacobian of x. Singular
// covariances are regularised by 1e-12 of their trace (an exact candidate wins).
UncertainPose covariance_intersection(const UncertainPose& a, const UncertainPose& b,
                                      double* omega_out = nullptr);

}  // namespace covtrack::client
