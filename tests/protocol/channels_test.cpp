// Channel names: the prefixes protocol/README.md documents, and the image channel a
// recording and `covtrack view --log` find camera frames on.
#include <gtest/gtest.h>

#include "covtrack/protocol/channel_pattern.hpp"
#include "covtrack/protocol/channels.hpp"

using namespace covtrack;

TEST(Channels, EachKindHasItsDocumentedName) {
  EXPECT_EQ(pose_channel("cam", "tag2"), "covtrack/pose/cam/tag2");
  EXPECT_EQ(raw_channel("cam"), "covtrack/raw/cam");
  EXPECT_EQ(image_channel("cam"), "covtrack/image/cam");
  EXPECT_TRUE(image_channel("cam").starts_with(kImagePrefix));
}

TEST(Channels, ImageChannelIsNeitherAPoseNorARawChannel) {
  const std::string image = image_channel("cam");
  EXPECT_FALSE(parse_pose_channel(image).has_value());
  EXPECT_FALSE(image.starts_with(kRawPrefix));
  EXPECT_FALSE(image.starts_with(kPosePrefix));
}

TEST(Channels, LongestImageChannelFitsLcmsLimit) {
  const std::string longest_name(kMaxNameLength, 'd');
  ASSERT_TRUE(is_valid_name(longest_name));
  EXPECT_LE(image_channel(longest_name).size(), 63u);
}

TEST(ChannelPattern, IsPosixExtendedAndSaysWhatIsWrong) {
  auto re = compile_channel_pattern("rig/(head|hand)[0-9]*");
  ASSERT_TRUE(re) << re.error().message;
  EXPECT_TRUE(std::regex_match("rig/hand12", *re));
  EXPECT_FALSE(std::regex_match("rig/hand12x", *re));
  const auto bad = compile_channel_pattern("rig/(?=head)");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("pattern 'rig/(?=head)' is not a POSIX extended regular expression"),
            std::string::npos) << bad.error().message;
}
