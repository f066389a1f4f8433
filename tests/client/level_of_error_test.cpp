// Level of Error switch: thresholds with hysteresis, unbounded and unknown assessments.
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "covtrack/client/level_of_error.hpp"

using covtrack::client::LevelOfError;

TEST(LevelOfError, SwitchesUpAtThresholdAndBackOnlyBelowTheMargin) {
  auto loe = LevelOfError::create({10, 30}, 2);
  ASSERT_TRUE(loe) << loe.error().message;
  const double inf = std::numeric_limits<double>::infinity();
  const struct {
    double assessment;
    int level;
  } steps[] = {
      {0, 0},    {9.9, 0},  {10, 1},  {9, 1},   {8.5, 1},  {8, 1},   {7.9, 0}, {10, 1},
      {29.9, 1}, {30, 2},   {28.5, 2}, {28, 2}, {27.9, 1}, {35, 2},  {5, 0},   {inf, 2},
      {9, 1},    {std::nan(""), 2},   {31, 2}, {0, 0}};
  int i = 0;
  for (const auto& s : steps) {
    EXPECT_EQ(loe->update(s.assessment), s.level) << "step " << i << ": " << s.assessment;
    EXPECT_EQ(loe->level(), s.level);
    ++i;
  }
}

TEST(LevelOfError, NoiseAroundAThresholdSwitchesOnceNotOnEveryCrossing) {
  auto loe = LevelOfError::create({20}, 1.5);
  ASSERT_TRUE(loe);
  auto plain = LevelOfError::create({20}, 0);  // no hysteresis: flickers
  ASSERT_TRUE(plain);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);  // within the margin
  int switches = 0, plain_switches = 0, last = 0, plain_last = 0;
  for (int k = 0; k < 1000; ++k) {
    const double a = 20 + noise(rng);
    const int level = loe->update(a), plain_level = plain->update(a);
    switches += level != last;
    plain_switches += plain_level != plain_last;
    last = level, plain_last = plain_level;
  }
  EXPECT_EQ(switches, 1);
  EXPECT_GT(plain_switches, 100) << "the noise crosses the threshold: the test means something";
}

TEST(LevelOfError, ChoosesTheAugmentationOfTheLevel) {
  auto loe = LevelOfError::create({5, 50}, 1);
  ASSERT_TRUE(loe);
  const std::string augmentations[] = {"overlay", "overlay with clues", "clues only"};
  EXPECT_EQ(loe->level_count(), 3);
  EXPECT_EQ(loe->choose(std::span<const std::string>(augmentations)), "overlay");
  loe->update(60);
  EXPECT_EQ(loe->choose(std::span<const std::string>(augmentations)), "clues only");
  loe->update(20);
  EXPECT_EQ(loe->choose(std::span<const std::string>(augmentations)), "overlay with clues");
}

TEST(LevelOfError, BadSettingsAreRefusedWithTheirPlace) {
  auto descending = LevelOfError::create({10, 5}, 1);
  ASSERT_FALSE(descending);
  EXPECT_NE(descending.error().message.find("threshold 1"), std::string::npos)
      << descending.error().message;
  auto equal = LevelOfError::create({10, 10}, 1);
  EXPECT_FALSE(equal);
  auto nan_threshold = LevelOfError::create({1, std::nan("")}, 1);
  ASSERT_FALSE(nan_threshold);
  EXPECT_NE(nan_threshold.error().message.find("not finite"), std::string::npos);
  auto negative_margin = LevelOfError::create({1}, -1);
  ASSERT_FALSE(negative_margin);
  EXPECT_NE(negative_margin.error().message.find("margin"), std::string::npos);
  EXPECT_FALSE(LevelOfError::create({1}, std::numeric_limits<double>::infinity()));
  auto single = LevelOfError::create({}, 0);  // one augmentation: always level 0
  ASSERT_TRUE(single);
  EXPECT_EQ(single->update(std::numeric_limits<double>::infinity()), 0);
}
