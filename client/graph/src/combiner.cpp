#include "covtrack/client/combiner.hpp"

#include <cmath>
#include <string>

namespace covtrack::client {
namespace {

double size_of(const Mat6& c, CovarianceSize size) {
  const Mat3 t = c.topLeftCorner<3, 3>();
  return size == CovarianceSize::TranslationTrace ? t.trace() : t.determinant();
}

// Information matrix of a covariance that may be singular (a static, exact edge).
Mat6 information(const Mat6& c) {
  const double eps = 1e-12 * std::max(c.trace(), 1e-300);
  return (c + eps * Mat6::Identity()).ldlt().solve(Mat6::Identity());
}

}  // namespace

UncertainPose covariance_intersection(const UncertainPose& a, const UncertainPose& b,
                                      double* omega_out) {
  const Vec6 d = boxminus(b.T, a.T);
  // a Exp(xi) = b Exp(xb) = a Exp(d) Exp(xb) ~ a Exp(d + Jr(d)^-1 xb)
  const Mat6 Jr_inv = se3_right_jacobian(d).inverse();
  const Mat6 Ia = information(a.covariance);
  const Mat6 Ib = information(Jr_inv * b.covariance * Jr_inv.transpose());

  auto fused_cov = [&](double w) -> Mat6 {
    return (w * Ia + (1 - w) * Ib).ldlt().solve(Mat6::Identity());
  };
  // trace(P(w)) is convex in w (Julier & Uhlmann), so golden section finds its minimum.
  const double g = (std::sqrt(5.0) - 1) / 2;
  double lo = 0, hi = 1;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double f1 = fused_cov(x1).trace(), f2 = fused_cov(x2).trace();
  for (int i = 0; i < 60 && hi - lo > 1e-6; ++i) {
    if (f1 < f2) {
      hi = x2; x2 = x1; f2 = f1; x1 = hi - g * (hi - lo); f1 = fused_cov(x1).trace();
    } else {
      lo = x1; x1 = x2; f1 = f2; x2 = lo + g * (hi - lo); f2 = fused_cov(x2).trace();
    }
  }
  double w = 0.5 * (lo + hi);
  // The ends are candidates too (one estimate dominating the other).
  for (double end : {0.0, 1.0})
    if (fused_cov(end).trace() < fused_cov(w).trace()) w = end;
  if (omega_out) *omega_out = w;

  const Mat6 P = fused_cov(w);
  const Vec6 x = P * ((1 - w) * Ib * d);
  // a Exp(x + e) ~ a Exp(x) Exp(Jr(x) e)
  const Mat6 Jr = se3_right_jacobian(x);
  UncertainPose out;
  out.T = boxplus(a.T, x);
  const Mat6 c = Jr * P * Jr.transpose();
  out.covariance = 0.5 * (c + c.transpose());
  return out;
}

Combiner Combiner::smallest(CovarianceSize size) {
  return Combiner([size](std::span<const UncertainPose> bounded) {
    Combined out;
    for (std::size_t i = 1; i < bounded.size(); ++i)
      if (size_of(bounded[i].covariance, size) < size_of(bounded[out.chosen].covariance, size))
        out.chosen = i;
    out.pose = bounded[out.chosen];
    return out;
  });
}

Combiner Combiner::covariance_intersection() {
  return Combiner([](std::span<const UncertainPose> bounded) {
    // Linearise around the tightest candidate: the smallest tangent-space distances.
    Combined out;
    for (std::size_t i = 1; i < bounded.size(); ++i)
      if (bounded[i].covariance.trace() < bounded[out.chosen].covariance.trace()) out.chosen = i;
    out.pose = bounded[out.chosen];
    for (std::size_t i = 0; i < bounded.size(); ++i) {
      if (i == out.chosen) continue;
      out.pose = client::covariance_intersection(out.pose, bounded[i]);
      out.fused = true;
    }
    return out;
  });
}

Combiner Combiner::callback(Callback callback) { return Combiner(std::move(callback)); }

Result<Combined> Combiner::combine(std::span<const UncertainPose> candidates) const {
  if (candidates.empty()) return fail("combiner: no candidate to choose from");
  std::vector<UncertainPose> bounded;
  std::vector<std::size_t> index_of;  // position in `candidates` of each bounded one
  for (std::size_t i = 0; i < candidates.size(); ++i)
    if (!candidates[i].unbounded) {
      bounded.push_back(candidates[i]);
      index_of.push_back(i);
    }
  if (bounded.empty()) {
    Combined out;
    out.pose = candidates.front();
    out.pose.unbounded = true;
    return out;
  }
  Combined out = policy_(bounded);
  if (out.chosen >= bounded.size())
    return fail("combiner: the policy chose candidate " + std::to_string(out.chosen) +
                " of " + std::to_string(bounded.size()) + " bounded ones");
  out.chosen = index_of[out.chosen];
  out.pose.unbounded = false;
  return out;
}

}  // namespace covtrack::client
