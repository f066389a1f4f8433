// The convention converters against Monte Carlo: draw body perturbations with the
// canonical covariance, measure the errors as the other convention defines them, and
// compare their sample covariance with the converted matrix.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>

#include "covtrack/protocol/covariance_conventions.hpp"

using namespace covtrack;

namespace {
constexpr int kSamples = 200000;

Mat6 test_covariance() {
  // Correlated, with position sigmas of centimetres and rotation sigmas of ~1-3 degrees.
  Eigen::Matrix<double, 6, 6> A;
  A << 0.02, 0, 0, 0, 0, 0, 0.005, 0.015, 0, 0, 0, 0, 0, 0.004, 0.01, 0, 0, 0,
      0.004, 0, 0, 0.02, 0, 0, 0, 0.006, 0, 0.01, 0.03, 0, 0, 0, 0.005, 0, 0.01, 0.05;
  return A * A.transpose();
}

Pose test_pose() {
  Pose T = Pose::Identity();
  T.linear() = so3_exp(Vec3(0.4, -1.1, 0.7));
  T.translation() = Vec3(1.0, -2.0, 0.5);
  return T;
}

template <typename ErrorOf>
Mat6 monte_carlo(const Mat6& cov_body, const Pose& T_est, ErrorOf error_of) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> n;
  const Mat6 L = cov_body.llt().matrixL();
  Mat6 sum = Mat6::Zero();
  for (int i = 0; i < kSamples; ++i) {
    Vec6 z;
    for (int k = 0; k < 6; ++k) z(k) = n(rng);
    const Pose T_true = T_est * se3_exp(L * z);
    const Vec6 e = error_of(T_true);
    sum += e * e.transpose();
  }
  return sum / kSamples;
}

double relative_error(const Mat6& a, const Mat6& b) { return (a - b).norm() / b.norm(); }
}  // namespace

TEST(CovarianceConventions, ParentFrameMatchesMonteCarlo) {
  const Mat6 cov = test_covariance();
  const Pose T = test_pose();
  const Mat6 mc = monte_carlo(cov, T, [&](const Pose& T_true) {
    Vec6 e;
    e << T_true.translation() - T.translation(), so3_log(T_true.linear() * T.linear().transpose());
    return e;
  });
  // 200k samples: the sampling error of the matrix is ~0.5%; first order adds a little.
  EXPECT_LT(relative_error(body_to_parent(T, cov), mc), 0.02);
  // A wrong converter (no rotation into the parent frame) fails clearly.
  EXPECT_GT(relative_error(cov, mc), 0.2);
}

TEST(CovarianceConventions, GtsamIsRotationFirstRightPerturbation) {
  const Mat6 cov = test_covariance();
  const Pose T = test_pose();
  const Mat6 mc = monte_carlo(cov, T, [&](const Pose& T_true) {
    const Vec6 xi = se3_log(T.inverse() * T_true);
    Vec6 e;
    e << xi.tail<3>(), xi.head<3>();
    return e;
  });
  EXPECT_LT(relative_error(body_to_gtsam(cov), mc), 0.02);
}

TEST(CovarianceConventions, RoundTripsAreExact) {
  const Mat6 cov = test_covariance();
  const Pose T = test_pose();
  for (auto c : {CovarianceConvention::Body, CovarianceConvention::Parent, CovarianceConvention::Gtsam}) {
    const Mat6 there = convert_covariance(T, cov, CovarianceConvention::Body, c);
    const Mat6 back = convert_covariance(T, there, c, CovarianceConvention::Body);
    EXPECT_LT((back - cov).norm(), 1e-15 * 1e6 * cov.norm());
  }
}

// protocol/README.md, "Worked example": the numbers printed there.
TEST(CovarianceConventions, ReadmeWorkedExample) {
  const Pose T = pose_from(Vec3(1, 0, 0), Eigen::Quaterniond(std::sqrt(0.5), 0, 0, std::sqrt(0.5)));
  Mat6 body = Mat6::Zero();
  body.diagonal() << 1e-6, 1e-4, 1e-4, 1e-6, 1e-6, 1e-6;
  Mat6 expected = Mat6::Zero();
  expected.diagonal() << 1e-4, 1e-6, 1e-4, 1e-6, 1e-6, 1e-6;
  EXPECT_LT((body_to_parent(T, body) - expected).norm(), 1e-15);
}
