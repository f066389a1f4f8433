#include "covtrack/protocol/se3_gaussian.hpp"

#include <Eigen/Eigenvalues>

namespace covtrack {

Se3Gaussian::Se3Gaussian(const Mat6& cov) {
  const Eigen::SelfAdjointEigenSolver<Mat6> eig(0.5 * (cov + cov.transpose()));
  sqrt_cov_ = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
}

Vec6 Se3Gaussian::draw(std::mt19937_64& rng) const {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec6 z;
  for (int i = 0; i < 6; ++i) z(i) = n(rng);
  return sqrt_cov_ * z;
}

}  // namespace covtrack
