// SE(3) maths against finite differences on the manifold.
#include <gtest/gtest.h>

#include <random>

#include "covtrack/protocol/se3.hpp"

using namespace covtrack;

namespace {
Vec6 random_xi(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Vec6 xi;
  for (int i = 0; i < 6; ++i) xi(i) = u(rng);
  return xi;
}
}  // namespace

TEST(Se3, ExpLogRoundTripIncludingSmallAndLargeAngles) {
  std::mt19937_64 rng(1);
  for (double scale : {1e-9, 1e-6, 1e-3, 0.5, 1.5}) {
    for (int i = 0; i < 200; ++i) {
      const Vec6 xi = random_xi(rng, scale);
      const Vec6 back = se3_log(se3_exp(xi));
      EXPECT_LT((back - xi).norm(), 1e-9 * std::max(1.0, xi.norm())) << "scale " << scale;
    }
  }
}

TEST(Se3, LogNearPiStaysOnTheShortBranch) {
  const Vec3 axis = Vec3(1, 2, 3).normalized();
  const Vec3 phi = (M_PI - 1e-7) * axis;
  EXPECT_NEAR(so3_log(so3_exp(phi)).norm(), M_PI - 1e-7, 1e-6);
}

TEST(Se3, AdjointMovesAPerturbationAcrossTheTransform) {
  std::mt19937_64 rng(2);
  for (int i = 0; i < 100; ++i) {
    const Pose T = se3_exp(random_xi(rng, 2.0));
    const Vec6 xi = random_xi(rng, 0.7);
    const Pose lhs = T * se3_exp(xi) * T.inverse();
    const Pose rhs = se3_exp(se3_adjoint(T) * xi);
    EXPECT_LT((lhs.matrix() - rhs.matrix()).norm(), 1e-9);
  }
}

// J_l(xi) d ~ Log(Exp(xi + d) Exp(xi)^-1) column by column, by central differences.
TEST(Se3, LeftAndRightJacobiansMatchFiniteDifferences) {
  std::mt19937_64 rng(3);
  const double h = 1e-6;
  for (double scale : {1e-5, 0.3, 1.2}) {
    for (int trial = 0; trial < 50; ++trial) {
      const Vec6 xi = random_xi(rng, scale);
      Mat6 numeric_left, numeric_right;
      for (int k = 0; k < 6; ++k) {
        const Vec6 d = Vec6::Unit(k) * h;
        numeric_left.col(k) = (se3_log(se3_exp(xi + d) * se3_exp(xi).inverse()) -
                               se3_log(se3_exp(xi - d) * se3_exp(xi).inverse())) / (2 * h);
        numeric_right.col(k) = (se3_log(se3_exp(xi).inverse() * se3_exp(xi + d)) -
                                se3_log(se3_exp(xi).inverse() * se3_exp(xi - d))) / (2 * h);
      }
      EXPECT_LT((numeric_left - se3_left_jacobian(xi)).cwiseAbs().maxCoeff(), 1e-6) << "scale " << scale;
      EXPECT_LT((numeric_right - se3_right_jacobian(xi)).cwiseAbs().maxCoeff(), 1e-6) << "scale " << scale;
    }
  }
}

TEST(Se3, BoxMinusInvertsBoxPlus) {
  std::mt19937_64 rng(4);
  const Pose T = se3_exp(random_xi(rng, 1.0));
  const Vec6 xi = random_xi(rng, 0.5);
  EXPECT_LT((boxminus(boxplus(T, xi), T) - xi).norm(), 1e-10);
}
