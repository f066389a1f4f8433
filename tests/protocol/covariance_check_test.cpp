#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>

#include <Eigen/QR>

#include "covtrack/protocol/covariance_check.hpp"

using namespace covtrack;

TEST(CovarianceCheck, AcceptsValidIncludingSingularAndTinyScales) {
  Mat6 c = Mat6::Identity() * 1e-8;
  EXPECT_FALSE(check_covariance(c));
  c(5, 5) = 0;  // no information about one axis is still a covariance
  EXPECT_FALSE(check_covariance(c));
  c(0, 1) = c(1, 0) = 0.5e-8;
  EXPECT_FALSE(check_covariance(c));
}

TEST(CovarianceCheck, RejectsEachDefect) {
  Mat6 c = Mat6::Identity() * 1e-4;
  c(2, 3) = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(check_covariance(c));
  EXPECT_EQ(check_covariance(c)->defect, CovarianceDefect::NonFinite);

  c = Mat6::Identity() * 1e-4;
  c(0, 4) = 1e-6;
  ASSERT_TRUE(check_covariance(c));
  EXPECT_EQ(check_covariance(c)->defect, CovarianceDefect::Asymmetric);

  c = Mat6::Identity() * 1e-4;
  c(0, 1) = c(1, 0) = 2e-4;  // correlation 2: eigenvalue -1e-4
  ASSERT_TRUE(check_covariance(c));
  EXPECT_EQ(check_covariance(c)->defect, CovarianceDefect::Indefinite);
}

// The verdict at the tolerance (smallest eigenvalue -1e-9 of the largest diagonal element)
// for random rotations: just inside is accepted, just outside refused.
TEST(CovarianceCheck, TheNegativeEigenvalueToleranceHoldsForAnyOrientation) {
  std::srand(7);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::HouseholderQR<Mat6> qr(Mat6::Random());
    const Mat6 q = qr.householderQ();
    for (const double factor : {-0.5, -2.0, 0.0, 0.5}) {
      Eigen::Matrix<double, 6, 1> eigenvalues;
      eigenvalues << 1e-9, 1e-6, 1e-4, 1e-3, 1e-2, 1.0;
      Mat6 c = q * eigenvalues.asDiagonal() * q.transpose();
      c = (c + c.transpose()).eval() / 2;
      eigenvalues(0) = factor * 1e-9 * c.diagonal().maxCoeff();
      c = q * eigenvalues.asDiagonal() * q.transpose();
      c = (c + c.transpose()).eval() / 2;
      const auto problem = check_covariance(c);
      EXPECT_EQ(problem.has_value(), factor < -1) << "factor " << factor << " trial " << trial;
      if (problem) {
        EXPECT_EQ(problem->defect, CovarianceDefect::Indefinite);
      }
    }
  }
}
