// The subscriber in one process over LCM's memq:// transport: the test publishes on the
// instance the Subscriber is attached to (memq reaches only its own instance).
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "covtrack/client/sequence_tracker.hpp"
#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/covariance_conventions.hpp"
#include "covtrack/protocol/message_auth.hpp"
#include "pose_messages.hpp"

using namespace covtrack;
using covtrack::test::pose_message;
using covtrack::test::test_covariance;
using namespace std::chrono_literals;

namespace {

class SubscriberTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(lcm_->good());
    open({});
  }
  void open(client::SubscriberOptions o) {
    sub_.reset();
    auto s = client::Subscriber::attach(lcm_, o);
    ASSERT_TRUE(s) << s.error().message;
    sub_ = std::move(*s);
  }
  void publish(const pose_cov_t& m) { lcm_->publish(pose_channel(m.device, m.sensor), &m); }
  // Waits until `pred` holds (up to 2 s).
  template <typename P>
  bool eventually(P pred) {
    for (int i = 0; i < 200; ++i) {
      if (pred()) return true;
      std::this_thread::sleep_for(10ms);
    }
    return pred();
  }
  client::StreamCounters counters(const char* d, const char* s) {
    auto st = sub_->stream({d, s});
    return st ? st->counters : client::StreamCounters{};
  }
  std::int64_t received(const char* d, const char* s) { return counters(d, s).received; }

  std::shared_ptr<lcm::LCM> lcm_ = std::make_shared<lcm::LCM>("memq://");
  std::unique_ptr<client::Subscriber> sub_;
};

}  // namespace

TEST_F(SubscriberTest, LatestValueAndCallbackCarryTheMessage) {
  std::atomic<int> calls{0};
  client::TrackedTransform seen;
  ASSERT_TRUE(sub_->on_pose("dev/.*", [&](const client::TrackedTransform& t) { seen = t; ++calls; }));
  EXPECT_FALSE(sub_->latest({"dev", "head"}));
  auto m = pose_message("dev", "head", 0);
  m.measurement_time_us = m.publish_time_us - 1500;
  publish(m);
  ASSERT_TRUE(eventually([&] { return calls == 1; }));
  auto latest = sub_->latest({"dev", "head"});
  ASSERT_TRUE(latest);
  EXPECT_EQ(latest->status, TrackingStatus::Ok);
  EXPECT_EQ(latest->parent_frame, "world");
  EXPECT_EQ(latest->child_frame, "head");
  EXPECT_EQ(latest->measurement_time_us, m.measurement_time_us);
  EXPECT_EQ(latest->publish_time_us, m.publish_time_us);
  EXPECT_LT((latest->T_parent_child.matrix() - test::test_pose().matrix()).norm(), 1e-12);
  EXPECT_LT((latest->covariance - test_covariance()).norm(), 1e-18);
  EXPECT_GE(latest->receive_time_us, latest->publish_time_us);
  EXPECT_NEAR(latest->age_s(m.measurement_time_us + 250000), 0.25, 1e-12);
  EXPECT_EQ(seen.stream.key(), "dev/head");
  EXPECT_EQ(seen.sequence, 0);
}

TEST_F(SubscriberTest, SubscriberPatternIsAWholeMatchOverDeviceSlashSensor) {
  open({.pattern = "a/x"});
  for (const char* d : {"b", "a", "aa"}) publish(pose_message(d, "x", 0));
  publish(pose_message("a", "xy", 0));
  publish(pose_message("a", "x", 1));  // after the others: when it is in, they were seen
  ASSERT_TRUE(eventually([&] { return received("a", "x") == 2; }));
  EXPECT_EQ(sub_->streams().size(), 1u);
  EXPECT_FALSE(sub_->stream({"a", "xy"}));
  EXPECT_FALSE(sub_->stream({"b", "x"}));
}

TEST_F(SubscriberTest, CallbackPatternsSelectStreams) {
  std::atomic<int> a_calls{0}, all_calls{0};
  ASSERT_TRUE(sub_->on_pose("a/.*", [&](const client::TrackedTransform&) { ++a_calls; }));
  ASSERT_TRUE(sub_->on_pose(".*", [&](const client::TrackedTransform&) { ++all_calls; }));
  EXPECT_FALSE(sub_->on_pose("(", [](const client::TrackedTransform&) {}));
  std::int64_t seq = 0;  // a repeated number would be a duplicate
  for (const char* d : {"a", "b", "ab", "a"}) publish(pose_message(d, "s", seq++));
  ASSERT_TRUE(eventually([&] { return all_calls == 4; }));
  EXPECT_EQ(a_calls, 2);
}

TEST_F(SubscriberTest, CallbackMayRegisterAnotherCallback) {
  std::atomic<int> inner{0};
  std::atomic<bool> registered{false};
  ASSERT_TRUE(sub_->on_pose(".*", [&](const client::TrackedTransform&) {
    if (!registered.exchange(true))
      (void)sub_->on_pose(".*", [&](const client::TrackedTransform&) { ++inner; });
  }));
  publish(pose_message("dev", "s", 0));
  publish(pose_message("dev", "s", 1));
  ASSERT_TRUE(eventually([&] { return inner == 1; }));  // only the second message
  std::this_thread::sleep_for(30ms);
  EXPECT_EQ(inner, 1);
}

TEST_F(SubscriberTest, SequenceGapsCountAsLostAndRestartsDoNot) {
  for (std::int64_t seq : {0, 1, 2, 6, 7}) publish(pose_message("dev", "s", seq));  // 3, 4, 5 lost
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 5; }));
  EXPECT_EQ(counters("dev", "s").lost, 3);
  // The daemon restarted: the new sequence is followed once it carries on alone.
  for (std::int64_t seq : {0, 1, 2}) publish(pose_message("dev", "s", seq));
  ASSERT_TRUE(eventually([&] { return counters("dev", "s").restarts == 1; }));
  EXPECT_EQ(received("dev", "s"), 6);  // 2 is delivered; 0 and 1 came before the restart was sure
  EXPECT_EQ(counters("dev", "s").foreign, client::SequenceTracker::kConfirm - 1);
  EXPECT_EQ(counters("dev", "s").lost, 3);
  publish(pose_message("dev", "s", 4));  // after the restart, gaps count again
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 7; }));
  EXPECT_EQ(counters("dev", "s").lost, 4);
  EXPECT_EQ(counters("other", "s").lost, 0);  // per stream
}

TEST_F(SubscriberTest, ForgedSequenceFarAheadIsForeignAndLossStaysTrue) {
  // A forged message 6.7e17 ahead once made `lost` jump by as much.
  for (std::int64_t seq : {0, 1}) publish(pose_message("dev", "s", seq));
  auto forged = pose_message("dev", "s", 670'000'000'000'000'000);
  forged.position_m[0] = 99;
  publish(forged);
  for (std::int64_t seq : {2, 3}) publish(pose_message("dev", "s", seq));
  publish(pose_message("dev", "s", std::numeric_limits<std::int64_t>::min()));  // and far behind
  publish(pose_message("dev", "s", 4));
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 5 && counters("dev", "s").foreign == 2; }));
  EXPECT_EQ(counters("dev", "s").lost, 0);
  EXPECT_EQ(counters("dev", "s").restarts, 0);
  EXPECT_EQ(sub_->latest({"dev", "s"})->sequence, 4);
  EXPECT_NE(sub_->latest({"dev", "s"})->T_parent_child.translation().x(), 99);  // never delivered
}

TEST_F(SubscriberTest, RejectedMessagesAreNotCountedAsLost) {
  auto bad = pose_message("dev", "s", 1);
  bad.covariance[0] = NAN;
  publish(pose_message("dev", "s", 0));
  publish(bad);
  publish(pose_message("dev", "s", 2));
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 2; }));
  EXPECT_EQ(counters("dev", "s").rejected, 1);
  EXPECT_EQ(counters("dev", "s").lost, 0);
}

TEST_F(SubscriberTest, StreamGoesStaleAfterTheTimeoutAndRecovers) {
  open({.stale_after_s = 0.15});
  publish(pose_message("dev", "s", 0));
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 1; }));
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(sub_->stream({"dev", "s"})->stale);
  ASSERT_TRUE(eventually([&] { return sub_->stream({"dev", "s"})->stale; }));
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 100ms);  // not before the timeout
  EXPECT_EQ(counters("dev", "s").stale, 1);
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(counters("dev", "s").stale, 1);  // counted once per episode
  publish(pose_message("dev", "s", 1));
  ASSERT_TRUE(eventually([&] { return !sub_->stream({"dev", "s"})->stale; }));
  ASSERT_TRUE(eventually([&] { return sub_->stream({"dev", "s"})->stale; }));
  EXPECT_EQ(counters("dev", "s").stale, 2);
  EXPECT_TRUE(sub_->latest({"dev", "s"}));  // stale keeps the last value
}

TEST_F(SubscriberTest, InvalidMessagesAreRejectedCountedAndNeverDelivered) {
  std::atomic<int> calls{0};
  ASSERT_TRUE(sub_->on_pose(".*", [&](const client::TrackedTransform&) { ++calls; }));
  auto nan = pose_message("dev", "s", 0);
  nan.covariance[7] = NAN;
  auto asymmetric = pose_message("dev", "s", 1);
  asymmetric.covariance[1] = 1e-3;
  auto indefinite = pose_message("dev", "s", 2);
  indefinite.covariance[1] = indefinite.covariance[6] = 1e-5;  // |correlation| > 1
  auto bad_quaternion = pose_message("dev", "s", 3);
  bad_quaternion.orientation_wxyz[0] *= 1.01;
  auto wrong_stream = pose_message("dev", "other", 4);  // published on dev/s below
  for (const auto& m : {nan, asymmetric, indefinite, bad_quaternion}) publish(m);
  lcm_->publish(pose_channel("dev", "s"), &wrong_stream);
  const std::uint8_t garbage[] = {1, 2, 3};
  lcm_->publish(pose_channel("dev", "s"), garbage, sizeof garbage);
  ASSERT_TRUE(eventually([&] { return counters("dev", "s").rejected == 6; }));
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(received("dev", "s"), 0);
  EXPECT_FALSE(sub_->latest({"dev", "s"}));
  EXPECT_NE(sub_->stream({"dev", "s"})->last_rejection.find("truncated"), std::string::npos);

  // A valid message is delivered; a later invalid one does not replace it.
  publish(pose_message("dev", "s", 5));
  publish(nan);
  ASSERT_TRUE(eventually([&] { return counters("dev", "s").rejected == 7; }));
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(sub_->latest({"dev", "s"})->sequence, 5);
}

TEST_F(SubscriberTest, MalformedMessagesAreCountedByReasonAndGoodOnesStillArrive) {
  // The messages that ended clients: a string length of 0 or less made LCM's decoder throw.
  std::vector<std::uint8_t> good(static_cast<std::size_t>(pose_message("dev", "s", 0).getEncodedSize()));
  pose_message("dev", "s", 0).encode(good.data(), 0, static_cast<int>(good.size()));
  const std::size_t device_length_at = 8 + 24;  // fingerprint, three int64
  for (std::uint8_t last : {0x00, 0xff}) {  // length 0, then -1
    auto bad = good;
    for (int i = 0; i < 4; ++i) bad[device_length_at + i] = i < 3 ? (last ? 0xff : 0x00) : last;
    lcm_->publish(pose_channel("dev", "s"), bad.data(), static_cast<unsigned>(bad.size()));
  }
  auto wrong_type = good;
  wrong_type[0] ^= 0x01;
  lcm_->publish(pose_channel("dev", "s"), wrong_type.data(), static_cast<unsigned>(wrong_type.size()));
  auto not_utf8 = pose_message("dev", "s", 0);
  not_utf8.parent_frame = "w\xff";  // ended `covtrack echo --json` (nlohmann type_error.316)
  publish(not_utf8);
  const std::uint8_t garbage[] = {1, 2, 3};
  lcm_->publish("covtrack/pose/not a stream", garbage, sizeof garbage);  // counted, yet no stream's
  lcm_->publish(status_channel("dev"), garbage, sizeof garbage);          // a heartbeat's turn
  publish(pose_message("dev", "s", 1));
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 1 && sub_->rejections().total == 6; }));
  const RejectionTally tally = sub_->rejections();
  EXPECT_EQ(tally.by_reason.at("bad length"), 2);
  EXPECT_EQ(tally.by_reason.at("wrong type"), 1);
  EXPECT_EQ(tally.by_reason.at("bad channel"), 1);
  EXPECT_EQ(tally.by_reason.at("truncated"), 1);
  EXPECT_EQ(tally.by_reason.at("bad text"), 1);
  EXPECT_NE(tally.last.find("covtrack/status/dev"), std::string::npos) << tally.last;
  EXPECT_EQ(counters("dev", "s").rejected, 4);
  EXPECT_EQ(counters("dev", "s").lost, 0);  // the malformed ones told nothing of the sequence
  EXPECT_EQ(sub_->streams().size(), 1u);
  EXPECT_TRUE(sub_->device_statuses().empty());
}

TEST_F(SubscriberTest, EachDefectIsNamedInTheRejection) {
  auto nan = pose_message("dev", "s", 0);
  nan.covariance[7] = NAN;
  auto asymmetric = pose_message("dev", "s", 1);
  asymmetric.covariance[1] = 1e-3;
  auto indefinite = pose_message("dev", "s", 2);
  indefinite.covariance[1] = indefinite.covariance[6] = 1e-5;
  auto bad_quaternion = pose_message("dev", "s", 3);
  bad_quaternion.orientation_wxyz[0] *= 1.01;
  int n = 0;
  for (const auto& m : {nan, asymmetric, indefinite, bad_quaternion}) {
    publish(m);
    ++n;
    ASSERT_TRUE(eventually([&] { return counters("dev", "s").rejected == n; }));
    EXPECT_FALSE(sub_->stream({"dev", "s"})->last_rejection.empty());
  }
  EXPECT_NE(sub_->stream({"dev", "s"})->last_rejection.find("quaternion"), std::string::npos);
}

TEST_F(SubscriberTest, LostIsAcceptedWithInfiniteUncertainty) {
  auto lost = pose_message("dev", "s", 0);
  lost.status = pose_cov_t::STATUS_LOST;
  for (double& v : lost.covariance) v = NAN;  // a LOST covariance is never checked
  for (double& v : lost.orientation_wxyz) v = 0;
  std::atomic<int> calls{0};
  ASSERT_TRUE(sub_->on_pose(".*", [&](const client::TrackedTransform&) { ++calls; }));
  publish(lost);
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 1; }));
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(counters("dev", "s").rejected, 0);
  auto t = sub_->latest({"dev", "s"});
  ASSERT_TRUE(t);
  EXPECT_TRUE(t->lost());
  EXPECT_FALSE(t->covariance.hasNaN());
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c)
      if (r == c) EXPECT_TRUE(std::isinf(t->covariance(r, c)) && t->covariance(r, c) > 0);
      else EXPECT_EQ(t->covariance(r, c), 0.0);
  EXPECT_FALSE(t->T_parent_child.matrix().hasNaN());
}

TEST_F(SubscriberTest, ParentAndGtsamConventionsArriveAsBody) {
  std::int64_t seq = 0;
  for (auto conv : {pose_cov_t::CONVENTION_PARENT, pose_cov_t::CONVENTION_GTSAM}) {
    auto m = pose_message("dev", "s", seq++);
    const Mat6 sent = convert_covariance(pose_of(m), test_covariance(), CovarianceConvention::Body,
                                         static_cast<CovarianceConvention>(conv));
    Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(m.covariance) = sent;
    m.covariance_convention = conv;
    ASSERT_GT((sent - test_covariance()).norm(), 1e-7);  // the conversion is not trivial
    publish(m);
    ASSERT_TRUE(eventually([&] { return received("dev", "s") == seq; }));
    const Mat6 expected = convert_covariance(pose_of(m), sent, static_cast<CovarianceConvention>(conv),
                                             CovarianceConvention::Body);
    EXPECT_LT((sub_->latest({"dev", "s"})->covariance - expected).norm(), 1e-18);
    EXPECT_LT((sub_->latest({"dev", "s"})->covariance - test_covariance()).norm(), 1e-15);
  }
}

TEST_F(SubscriberTest, DeviceHeartbeatsAreKeptPerDevice) {
  for (auto [device, reports] : {std::pair{"dev", 41}, {"other", 7}, {"dev", 42}}) {
    device_status_t st{};
    st.device = device;
    st.reports = reports;
    st.heartbeat_period_us = 1'000'000;
    lcm_->publish(status_channel(device), &st);
  }
  ASSERT_TRUE(eventually([&] {
    auto s = sub_->device_statuses();
    return s.count("dev") && s.at("dev").reports == 42 && s.count("other");
  }));
  EXPECT_EQ(sub_->device_statuses().size(), 2u);
}

TEST_F(SubscriberTest, QuietDeviceStaysReachableAndSilentOneIsReportedLost) {
  open({.stale_after_s = 0.05});
  std::atomic<int> unreachable_reports{0};
  ASSERT_TRUE(sub_->on_pose(".*", [&](const client::TrackedTransform& t) { unreachable_reports += t.device_unreachable; }));
  device_status_t st{};
  st.device = "dev";
  st.heartbeat_period_us = 100'000;  // unreachable after 0.3 s without one: far beyond the 10 ms pace below
  publish(pose_message("dev", "s", 0));
  // Quiet: heartbeats go on, no pose. The stream goes stale; the device stays reachable.
  for (int i = 0; i < 30; ++i) {
    lcm_->publish(status_channel("dev"), &st);
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(eventually([&] { return sub_->stream({"dev", "s"})->stale; }));
  EXPECT_TRUE(sub_->devices().at("dev").reachable);
  EXPECT_EQ(unreachable_reports, 0);
  EXPECT_FALSE(sub_->latest({"dev", "s"})->lost());
  // Dead: the heartbeats stop too.
  ASSERT_TRUE(eventually([&] { return unreachable_reports == 1; }));
  EXPECT_FALSE(sub_->devices().at("dev").reachable);
  EXPECT_TRUE(sub_->latest({"dev", "s"})->lost());
  EXPECT_TRUE(sub_->latest({"dev", "s"})->device_unreachable);
  EXPECT_EQ(sub_->latest({"dev", "s"})->sequence, 0);  // the last message's, not a new one
  // Back: a heartbeat makes it reachable; the next pose replaces the LOST report.
  lcm_->publish(status_channel("dev"), &st);
  publish(pose_message("dev", "s", 1));
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 2; }));
  EXPECT_TRUE(sub_->devices().at("dev").reachable);
  EXPECT_FALSE(sub_->latest({"dev", "s"})->device_unreachable);
}

TEST_F(SubscriberTest, StopsPromptlyWhenIdleAndDeliversNothingAfter) {
  std::atomic<int> calls{0};
  ASSERT_TRUE(sub_->on_pose(".*", [&](const client::TrackedTransform&) { ++calls; }));
  std::this_thread::sleep_for(50ms);  // the thread is idle in poll()
  const auto t0 = std::chrono::steady_clock::now();
  sub_->stop();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 100ms);
  sub_->stop();  // idempotent
  publish(pose_message("dev", "s", 0));
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(calls, 0);
  const auto t1 = std::chrono::steady_clock::now();
  sub_.reset();
  EXPECT_LT(std::chrono::steady_clock::now() - t1, 100ms);
}

TEST(Subscriber, BadUrlAndBadPatternFailAtOnce) {
  EXPECT_FALSE(client::Subscriber::open({.lcm_url = "memq://", .pattern = "("}));
  auto r = client::Subscriber::open({.lcm_url = "udpm://10.0.0.1:7667"});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("not a multicast group"), std::string::npos);
  EXPECT_FALSE(client::Subscriber::attach(nullptr, {}));
}

// Through an lcm::LCM instance (memq), as over udpm: with a key, signed messages are
// delivered, and unsigned, forged and repeated ones are counted and never reach a stream.
TEST_F(SubscriberTest, WithAKeyOnlyAuthenticFreshMessagesAreDelivered) {
  const std::string key_file = ::testing::TempDir() + "/subscriber_test_" + std::to_string(::getpid()) + ".key";
  ::unlink(key_file.c_str());
  ASSERT_TRUE(write_new_auth_key(key_file));
  open({.key_file = key_file});
  const auto key = load_auth_key(key_file);
  ASSERT_TRUE(key);
  MessageSigner signer(*key, 5);
  const std::string channel = pose_channel("dev", "s");
  auto publish_bytes = [&](const pose_cov_t& m, bool sign) {
    auto bytes = test::encoded(m);
    if (sign) signer.sign(channel, bytes);
    lcm_->publish(channel, bytes.data(), static_cast<unsigned>(bytes.size()));
    return bytes;
  };
  publish_bytes(pose_message("dev", "s", 0), true);
  const auto second = publish_bytes(pose_message("dev", "s", 1), true);
  publish_bytes(pose_message("dev", "s", 2), false);                          // unauthenticated
  auto forged = second;
  forged[40] ^= 1;
  lcm_->publish(channel, forged.data(), static_cast<unsigned>(forged.size()));  // forged
  lcm_->publish(channel, second.data(), static_cast<unsigned>(second.size()));  // replayed
  publish_bytes(pose_message("dev", "s", 2), true);
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 3; }));
  const auto auth = sub_->authentication();
  ASSERT_TRUE(auth);
  EXPECT_EQ(auth->authenticated, 3);
  EXPECT_EQ(auth->unauthenticated, 1);
  EXPECT_EQ(auth->forged, 1);
  EXPECT_EQ(auth->replayed, 1);
  EXPECT_EQ(counters("dev", "s").rejected, 0);
  EXPECT_EQ(counters("dev", "s").foreign, 0);
  EXPECT_EQ(sub_->rejections().total, 3);
}

TEST_F(SubscriberTest, AnUnusableKeyFileOrMaxAgeIsRefusedAtOpen) {
  const std::string key_file = ::testing::TempDir() + "/subscriber_test_age_" + std::to_string(::getpid()) + ".key";
  ::unlink(key_file.c_str());
  ASSERT_TRUE(write_new_auth_key(key_file));
  sub_.reset();
  for (double age : {0.0, -1.0, std::numeric_limits<double>::infinity(), std::nan("")}) {
    auto s = client::Subscriber::attach(lcm_, {.key_file = key_file, .auth_max_age_s = age});
    ASSERT_FALSE(s) << age;
    EXPECT_NE(s.error().message.find("auth_max_age_s"), std::string::npos) << s.error().message;
  }
  auto missing = client::Subscriber::attach(lcm_, {.key_file = key_file + ".absent"});
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("No such file"), std::string::npos) << missing.error().message;
  EXPECT_TRUE(client::Subscriber::attach(lcm_, {.key_file = key_file}));
}
