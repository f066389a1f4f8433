#include "graph_fusion.hpp"

#include <algorithm>
#include <map>

namespace covtrack::client::fusion {
namespace {

// Sums sensitivities of the same edge; the result is sorted by edge, which
// cross_covariance relies on.
class TermSum {
 public:
  void add(const Mat6& left, const std::vector<Sensitivity>& terms) {
    for (const auto& t : terms) {
      auto [it, inserted] = sum_.try_emplace(t.edge, Mat6::Zero());
      it->second.noalias() += left * t.J;
    }
  }
  std::vector<Sensitivity> take() {
    std::vector<Sensitivity> out;
    out.reserve(sum_.size());
    for (auto& [edge, J] : sum_) out.push_back({edge, J});
    return out;
  }

 private:
  std::map<EdgeKey, Mat6> sum_;
};

}  // namespace

LinearEstimate compose(std::span<const LinearFactor> factors) {
  Pose suffix = Pose::Identity();
  TermSum terms;
  for (auto it = factors.rbegin(); it != factors.rend(); ++it) {
    const Pose& T = it->estimate->T;
    Mat6 J;
    if (it->inverted) {
      suffix = T.inverse() * suffix;
      J = -se3_adjoint(suffix.inverse());
    } else {
      J = se3_adjoint(suffix.inverse());
      suffix = T * suffix;
    }
    terms.add(J, it->estimate->terms);
  }
  return {suffix, terms.take()};
}

Mat6 cross_covariance(const LinearEstimate& a, const LinearEstimate& b, const EdgeCovariance& C) {
  Mat6 out = Mat6::Zero();
  auto ia = a.terms.begin(), ib = b.terms.begin();
  while (ia != a.terms.end() && ib != b.terms.end()) {
    if (ia->edge < ib->edge) {
      ++ia;
    } else if (ib->edge < ia->edge) {
      ++ib;
    } else {
      out.noalias() += ia->J * C(ia->edge) * ib->J.transpose();
      ++ia, ++ib;
    }
  }
  return out;
}

LinearEstimate fuse(std::span<const LinearEstimate> estimates, const EdgeCovariance& C,
                    std::size_t* base_out) {
  const std::size_t n = estimates.size();
  std::size_t base = 0;
  std::vector<double> traces(n);
  for (std::size_t k = 0; k < n; ++k) {
    traces[k] = covariance(estimates[k], C).trace();
    if (traces[k] < traces[base]) base = k;
  }
  if (base_out) *base_out = base;
  if (n == 1) return estimates[0];

  // Each estimate as an offset from the base: T_k = T_base Exp(z_k), its error moved into
  // the base's tangent space by the inverse right Jacobian.
  std::vector<LinearEstimate> moved(n);
  Eigen::VectorXd z(6 * n);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec6 d = boxminus(estimates[k].T, estimates[base].T);
    z.segment<6>(6 * k) = d;
    TermSum terms;
    terms.add(se3_right_jacobian(d).inverse(), estimates[k].terms);
    moved[k] = {estimates[k].T, terms.take()};
  }
  Eigen::MatrixXd R(6 * n, 6 * n);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t l = k; l < n; ++l) {
      const Mat6 block = cross_covariance(moved[k], moved[l], C);
      R.block<6, 6>(6 * k, 6 * l) = block;
      R.block<6, 6>(6 * l, 6 * k) = block.transpose();
    }
  // An exact path (all its edges static with zero covariance) or two paths over the same
  // edges make R singular; a relative nudge keeps the solve defined and lets the exact
  // one win.
  R.diagonal().array() += 1e-12 * std::max(R.trace() / double(6 * n), 1e-300);
  Eigen::MatrixXd H(6 * n, 6);
  for (std::size_t k = 0; k < n; ++k) H.block<6, 6>(6 * k, 0).setIdentity();
  const Eigen::LDLT<Eigen::MatrixXd> R_ldlt(R);
  const Eigen::MatrixXd Rinv_H = R_ldlt.solve(H);
  const Mat6 P = (H.transpose() * Rinv_H).ldlt().solve(Mat6::Identity());
  const Eigen::MatrixXd W = P * Rinv_H.transpose();  // 6 x 6n, sums to I over its blocks
  const Vec6 x = W * z;

  // The fused error is Jr(x) sum_k W_k (error of estimate k in the base's tangent space).
  const Mat6 Jr = se3_right_jacobian(x);
  TermSum terms;
  for (std::size_t k = 0; k < n; ++k) terms.add(Jr * W.block<6, 6>(0, 6 * k), moved[k].terms);
  return {boxplus(estimates[base].T, x), terms.take()};
}

}  // namespace covtrack::client::fusion
