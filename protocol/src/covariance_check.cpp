#include "covtrack/protocol/covariance_check.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

namespace covtrack {
namespace {
constexpr double kRelativeAsymmetry = 1e-9;
constexpr double kRelativeNegativeEigenvalue = 1e-9;

std::string at(int r, int c, double v) {
  return "element (" + std::to_string(r) + "," + std::to_string(c) + ") = " + std::to_string(v);
}
}  // namespace

std::optional<CovarianceProblem> check_covariance(const Mat6& cov) {
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c)
      if (!std::isfinite(cov(r, c)))
        return CovarianceProblem{CovarianceDefect::NonFinite, at(r, c, cov(r, c))};

  const double scale = cov.diagonal().cwiseAbs().maxCoeff();
  for (int r = 0; r < 6; ++r)
    for (int c = r + 1; c < 6; ++c)
      if (std::abs(cov(r, c) - cov(c, r)) > kRelativeAsymmetry * scale)
        return CovarianceProblem{CovarianceDefect::Asymmetric,
                                 at(r, c, cov(r, c)) + " but " + at(c, r, cov(c, r))};

  // The smallest eigenvalue is at least -tolerance exactly when cov + tolerance * I is
  // positive semi-definite. A Cholesky factorisation of it succeeds for nearly every
  // valid covariance at a few percent of an eigensolver's cost (it runs on every received
  // message); the eigensolver decides the rest and names the offending eigenvalue.
  const double tolerance = kRelativeNegativeEigenvalue * scale;
  if (Eigen::LLT<Mat6>(cov + tolerance * Mat6::Identity()).info() == Eigen::Success) return std::nullopt;
  const Eigen::SelfAdjointEigenSolver<Mat6> eig(cov, Eigen::EigenvaluesOnly);
  const double smallest = eig.eigenvalues()(0);
  if (smallest < -tolerance)
    return CovarianceProblem{CovarianceDefect::Indefinite,
                             "smallest eigenvalue " + std::to_string(smallest)};
  return std::nullopt;
}

const char* to_string(CovarianceDefect defect) {
  switch (defect) {
    case CovarianceDefect::NonFinite: return "non-finite";
    case CovarianceDefect::Asymmetric: return "asymmetric";
    case CovarianceDefect::Indefinite: return "not positive semi-definite";
  }
  return "?";
}

}  // namespace covtrack
