#include <gtest/gtest.h>

#include <limits>

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
