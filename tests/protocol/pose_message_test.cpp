// The pose message as it goes on the wire: a LOST report's matrix survives encoding as
// diag(+inf) with exact zeros elsewhere, so consumers in any language read no NaN.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "covtrack/protocol/pose_message.hpp"

using namespace covtrack;

TEST(PoseMessage, LostCovarianceIsInfiniteDiagonalAndZeroElsewhere) {
  const Mat6 cov = lost_covariance();
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c)
      if (r == c) EXPECT_TRUE(std::isinf(cov(r, c)) && cov(r, c) > 0) << r;
      else EXPECT_EQ(cov(r, c), 0.0) << r << "," << c;
}

TEST(PoseMessage, LostCovarianceSurvivesEncoding) {
  pose_cov_t msg{};
  msg.status = pose_cov_t::STATUS_LOST;
  set_pose(msg, pose_from(Vec3(1, 2, 3), Eigen::Quaterniond::Identity()), lost_covariance());
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  ASSERT_EQ(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  pose_cov_t back{};
  ASSERT_EQ(back.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  for (int i = 0; i < 36; ++i) {
    EXPECT_FALSE(std::isnan(back.covariance[i])) << "entry " << i;
    EXPECT_EQ(back.covariance[i], i % 7 == 0 ? INFINITY : 0.0) << "entry " << i;
  }
}
