// Authentication trailers, key files and the replay guard: an authentic message passes
// and decodes as it was; every change of its bytes, its channel or its key is a forgery;
// a message cut short of its trailer has none; a key file others can read is refused.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <vector>

#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/message_auth.hpp"
#include "covtrack/protocol/replay_guard.hpp"
#include "covtrack/protocol/wire_decode.hpp"
#include "client/pose_messages.hpp"

using namespace covtrack;

namespace {

const std::string kChannel = "covtrack/pose/dev/head";

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "/message_auth_" + std::to_string(::getpid()) + "_" + name;
}

AuthKey new_key(const std::string& name) {
  const std::string path = temp_path(name);
  ::unlink(path.c_str());
  EXPECT_TRUE(write_new_auth_key(path));
  auto key = load_auth_key(path);
  EXPECT_TRUE(key) << key.error().message;
  return key.value_or(AuthKey{});
}

std::vector<std::uint8_t> encoded_pose() { return test::encoded(test::pose_message("dev", "head", 7)); }

std::span<const std::byte> bytes(const std::vector<std::uint8_t>& v) { return bytes_of(v.data(), v.size()); }

std::vector<std::uint8_t> signed_pose(const AuthKey& key, std::uint64_t counter = 1, std::int64_t sent_us = 1000) {
  auto message = encoded_pose();
  append_auth_trailer(key, kChannel, {0xabcdef, counter, sent_us}, message);
  return message;
}

}  // namespace

TEST(MessageAuth, AnAuthenticMessagePassesAndDecodesAsItWas) {
  const AuthKey key = new_key("a");
  const auto plain = encoded_pose();
  const auto message = signed_pose(key, 5, 123456);
  ASSERT_EQ(message.size(), plain.size() + kAuthTrailerBytes);
  const auto checked = authenticate(key, kChannel, bytes(message));
  ASSERT_TRUE(checked);
  EXPECT_EQ(checked->message.size(), plain.size());
  EXPECT_EQ(checked->trailer.instance_id, 0xabcdefu);
  EXPECT_EQ(checked->trailer.counter, 5u);
  EXPECT_EQ(checked->trailer.sent_us, 123456);
  // A program without the key decodes it too: the trailer is not a trailing-bytes fault.
  const auto decoded = decode_message<pose_cov_t>(bytes(message));
  ASSERT_TRUE(decoded) << decoded.error().describe();
  EXPECT_EQ(decoded->sequence, 7);
  // And LCM's own decoder reads the message part and leaves the trailer.
  pose_cov_t raw;
  EXPECT_EQ(raw.decode(message.data(), 0, static_cast<int>(message.size())), static_cast<int>(plain.size()));
}

TEST(MessageAuth, EveryAlteredByteIsAForgery) {
  const AuthKey key = new_key("b");
  const auto message = signed_pose(key);
  // Every byte but the magic's (altered, there is no trailer left: Missing).
  for (std::size_t i = 0; i + 4 < message.size(); ++i) {
    auto altered = message;
    altered[i] ^= 0x01;
    const auto checked = authenticate(key, kChannel, bytes(altered));
    ASSERT_FALSE(checked) << "byte " << i;
    EXPECT_EQ(checked.error(), AuthFault::Forged) << "byte " << i;
  }
}

TEST(MessageAuth, AnotherKeyOrChannelIsAForgery) {
  const AuthKey key = new_key("c"), other = new_key("d");
  const auto message = signed_pose(key);
  EXPECT_EQ(authenticate(other, kChannel, bytes(message)).error(), AuthFault::Forged);
  EXPECT_EQ(authenticate(key, "covtrack/pose/dev/hand", bytes(message)).error(), AuthFault::Forged);
}

TEST(MessageAuth, NoTrailerOrACutOneIsMissing) {
  const AuthKey key = new_key("e");
  EXPECT_EQ(authenticate(key, kChannel, bytes(encoded_pose())).error(), AuthFault::Missing);
  auto cut = signed_pose(key);
  cut.pop_back();
  EXPECT_EQ(authenticate(key, kChannel, bytes(cut)).error(), AuthFault::Missing);
  EXPECT_EQ(authenticate(key, kChannel, {}).error(), AuthFault::Missing);
  // Without a key, a cut trailer is bytes after the last field, as before.
  EXPECT_EQ(decode_message<pose_cov_t>(bytes(cut)).error().fault, WireFault::TrailingBytes);
}

TEST(MessageAuth, SignerCountsUpAcrossChannels) {
  const AuthKey key = new_key("f");
  MessageSigner signer(key, 99);
  auto first = encoded_pose(), second = encoded_pose();
  signer.sign(kChannel, first);
  signer.sign("covtrack/status/dev", second);
  const auto a = authenticate(key, kChannel, bytes(first));
  const auto b = authenticate(key, "covtrack/status/dev", bytes(second));
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->trailer.instance_id, 99u);
  EXPECT_EQ(b->trailer.counter, a->trailer.counter + 1);
}

TEST(KeyFile, RefusedWhenOthersMayReadItOrItIsNoKey) {
  const std::string path = temp_path("perm");
  ::unlink(path.c_str());
  ASSERT_TRUE(write_new_auth_key(path));
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_FALSE(write_new_auth_key(path)) << "an existing key file must not be overwritten";
  ::chmod(path.c_str(), 0640);  // a group may share it
  EXPECT_TRUE(load_auth_key(path));
  ::chmod(path.c_str(), 0644);
  const auto refused = load_auth_key(path);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("chmod o-rwx"), std::string::npos) << refused.error().message;

  const std::string bad = temp_path("bad");
  for (const std::string& text : std::vector<std::string>{"", "00", std::string(64, 'g'), std::string(66, '0')}) {
    ::unlink(bad.c_str());
    std::ofstream(bad) << text;
    ::chmod(bad.c_str(), 0600);
    const auto key = load_auth_key(bad);
    ASSERT_FALSE(key) << text;
    EXPECT_NE(key.error().message.find("hexadecimal"), std::string::npos) << key.error().message;
  }
  EXPECT_FALSE(load_auth_key(::testing::TempDir()));  // a directory
  EXPECT_FALSE(load_auth_key(temp_path("absent")));
}

TEST(ReplayGuard, RefusesRepeatsAndOldMessagesAcceptsNewSenders) {
  ReplayGuard guard(2.0);
  const std::int64_t now = 1'000'000'000;
  EXPECT_FALSE(guard.check(kChannel, {1, 10, now}, now));
  EXPECT_TRUE(guard.check(kChannel, {1, 10, now}, now)) << "the same counter again";
  EXPECT_TRUE(guard.check(kChannel, {1, 9, now}, now)) << "an earlier counter";
  EXPECT_FALSE(guard.check(kChannel, {1, 12, now}, now)) << "a gap is loss, not a replay";
  EXPECT_FALSE(guard.check("covtrack/status/dev", {1, 11, now}, now)) << "counters are per channel";
  EXPECT_FALSE(guard.check(kChannel, {2, 1, now}, now)) << "a restarted daemon: a new instance";
  EXPECT_TRUE(guard.check(kChannel, {3, 1, now - 2'500'000}, now)) << "older than the limit";
  EXPECT_TRUE(guard.check(kChannel, {3, 1, now + 2'500'000}, now)) << "from the future";
  EXPECT_FALSE(guard.check(kChannel, {3, 1, now - 1'500'000}, now));
  // An instance silent past the limit is forgotten; its messages are then refused by age.
  const std::int64_t later = now + 10'000'000;
  EXPECT_FALSE(guard.check(kChannel, {4, 1, later}, later));
  EXPECT_TRUE(guard.check(kChannel, {1, 13, now}, later));
}
