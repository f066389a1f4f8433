// The subscriber on LCM's in-process memq:// transport, and `covtrack echo` as a process
// over multicast inside a private network namespace (the test binary runs in one).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "covtrack/client/subscriber.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/clock.hpp"

using namespace covtrack;
using namespace std::chrono_literals;

namespace {

Mat6 test_covariance() {
  Mat6 c = Mat6::Zero();
  c.diagonal() << 1e-6, 2e-6, 3e-6, 1e-5, 2e-5, 3e-5;
  c(0, 1) = c(1, 0) = 5e-7;
  return c;
}

pose_cov_t message(const std::string& device, const std::string& sensor, std::int64_t seq) {
  pose_cov_t m{};
  m.device = device;
  m.sensor = sensor;
  m.parent_frame = "world";
  m.child_frame = sensor;
  m.sequence = seq;
  m.measurement_time_us = m.publish_time_us = now_us();
  Pose T = Pose::Identity();
  T.linear() = so3_exp(Vec3(0.1, 0.2, 0.3));
  T.translation() = Vec3(1, 2, 3);
  set_pose(m, T, test_covariance());
  return m;
}

const std::string kUrl = "udpm://239.255.76.67:7711?ttl=0";

// Real multicast inside the test's private network namespace: the publisher is a
// separate LCM instance, as a daemon would be.
class SubscriberTest : public ::testing::Test {
 protected:
  void SetUp() override { open({}); }
  void open(client::SubscriberOptions o) {
    o.lcm_url = kUrl;
    sub_.reset();
    auto s = client::Subscriber::open(o);
    ASSERT_TRUE(s) << s.error().message;
    sub_ = std::move(*s);
  }
  void publish(const pose_cov_t& m) { publisher_.publish(pose_channel(m.device, m.sensor), &m); }
  // Waits until `pred` holds (up to 2 s).
  template <typename P>
  bool eventually(P pred) {
    for (int i = 0; i < 200; ++i) {
      if (pred()) return true;
      std::this_thread::sleep_for(10ms);
    }
    return pred();
  }
  std::int64_t received(const char* d, const char* s) {
    auto st = sub_->stream({d, s});
    return st ? st->counters.received : 0;
  }
  lcm::LCM publisher_{kUrl};
  std::unique_ptr<client::Subscriber> sub_;
};

}  // namespace

TEST_F(SubscriberTest, LatestValueAndCallbackCarryTheMessage) {
  std::atomic<int> calls{0};
  client::TrackedTransform seen;
  ASSERT_TRUE(sub_->on_pose("dev/.*", [&](const client::TrackedTransform& t) { seen = t; ++calls; }));
  publish(message("dev", "head", 0));
  ASSERT_TRUE(eventually([&] { return calls == 1; }));
  auto latest = sub_->latest({"dev", "head"});
  ASSERT_TRUE(latest);
  EXPECT_EQ(latest->status, TrackingStatus::Ok);
  EXPECT_LT((latest->T_parent_child.translation() - Vec3(1, 2, 3)).norm(), 1e-12);
  EXPECT_LT((latest->covariance - test_covariance()).norm(), 1e-18);
  EXPECT_EQ(seen.stream.key(), "dev/head");
  EXPECT_GE(latest->receive_time_us, latest->publish_time_us);
}

TEST_F(SubscriberTest, PatternSelectsStreams) {
  open({.pattern = "a/.*"});
  publish(message("b", "x", 0));
  publish(message("a", "x", 0));
  ASSERT_TRUE(eventually([&] { return received("a", "x") == 1; }));
  std::this_thread::sleep_for(50ms);
  EXPECT_FALSE(sub_->stream({"b", "x"}));
}

TEST_F(SubscriberTest, SequenceGapsCountAsLostAndRestartsDoNot) {
  for (std::int64_t seq : {0, 1, 2, 6, 7}) publish(message("dev", "s", seq));  // 3, 4, 5 lost
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 5; }));
  EXPECT_EQ(sub_->stream({"dev", "s"})->counters.lost, 3);
  for (std::int64_t seq : {0, 1}) publish(message("dev", "s", seq));  // the daemon restarted
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 7; }));
  EXPECT_EQ(sub_->stream({"dev", "s"})->counters.lost, 3);
}

TEST_F(SubscriberTest, StreamGoesStaleAndRecovers) {
  open({.stale_after_s = 0.1});
  publish(message("dev", "s", 0));
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 1; }));
  EXPECT_FALSE(sub_->stream({"dev", "s"})->stale);
  ASSERT_TRUE(eventually([&] { return sub_->stream({"dev", "s"})->stale; }));
  EXPECT_EQ(sub_->stream({"dev", "s"})->counters.stale, 1);
  publish(message("dev", "s", 1));
  ASSERT_TRUE(eventually([&] { return !sub_->stream({"dev", "s"})->stale; }));
}

TEST_F(SubscriberTest, InvalidMessagesAreRejectedCountedAndNeverDelivered) {
  std::atomic<int> calls{0};
  ASSERT_TRUE(sub_->on_pose(".*", [&](const client::TrackedTransform&) { ++calls; }));
  auto nan = message("dev", "s", 0);
  nan.covariance[7] = NAN;
  auto asymmetric = message("dev", "s", 1);
  asymmetric.covariance[1] = 1e-3;
  auto indefinite = message("dev", "s", 2);
  indefinite.covariance[1] = indefinite.covariance[6] = 1e-5;  // |corr| > 1
  auto bad_quaternion = message("dev", "s", 3);
  bad_quaternion.orientation_wxyz[0] = 2;
  for (const auto& m : {nan, asymmetric, indefinite, bad_quaternion}) publish(m);
  const std::uint8_t garbage[] = {1, 2, 3};
  publisher_.publish(pose_channel("dev", "s"), garbage, sizeof garbage);
  ASSERT_TRUE(eventually([&] {
    auto st = sub_->stream({"dev", "s"});
    return st && st->counters.rejected == 5;
  }));
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(sub_->latest({"dev", "s"}));
  EXPECT_NE(sub_->stream({"dev", "s"})->last_rejection.find("malformed"), std::string::npos);
}

TEST_F(SubscriberTest, LostIsAcceptedWithInfiniteUncertainty) {
  auto lost = message("dev", "s", 0);
  lost.status = pose_cov_t::STATUS_LOST;
  for (double& v : lost.covariance) v = 0;
  for (int i = 0; i < 6; ++i) lost.covariance[7 * i] = INFINITY;
  publish(lost);
  ASSERT_TRUE(eventually([&] { return received("dev", "s") == 1; }));
  auto t = sub_->latest({"dev", "s"});
  EXPECT_TRUE(t->lost());
  EXPECT_TRUE(std::isinf(t->covariance(0, 0)));
}

TEST_F(SubscriberTest, OtherConventionsArriveAsBody) {
  for (auto [conv, seq] : {std::pair{pose_cov_t::CONVENTION_PARENT, 0}, {pose_cov_t::CONVENTION_GTSAM, 1}}) {
    auto m = message("dev", "s", seq);
    const Mat6 sent = convert_covariance(pose_of(m), test_covariance(), CovarianceConvention::Body,
                                         static_cast<CovarianceConvention>(conv));
    Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(m.covariance) = sent;
    m.covariance_convention = conv;
    ASSERT_GT((sent - test_covariance()).norm(), 1e-7);  // the conversion is not trivial
    publish(m);
    ASSERT_TRUE(eventually([&] { return received("dev", "s") == seq + 1; }));
    EXPECT_LT((sub_->latest({"dev", "s"})->covariance - test_covariance()).norm(), 1e-15);
  }
}

TEST_F(SubscriberTest, DeviceHeartbeatsAreKept) {
  device_status_t st{};
  st.device = "dev";
  st.reports = 42;
  publisher_.publish(status_channel("dev"), &st);
  ASSERT_TRUE(eventually([&] { return sub_->device_statuses().count("dev") == 1; }));
  EXPECT_EQ(sub_->device_statuses().at("dev").reports, 42);
}

TEST_F(SubscriberTest, StopsPromptlyWhenIdle) {
  const auto t0 = std::chrono::steady_clock::now();
  sub_->stop();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 200ms);
}

TEST(Subscriber, BadUrlAndBadPatternFailAtOnce) {
  EXPECT_FALSE(client::Subscriber::open({.lcm_url = kUrl, .pattern = "("}));
  auto r = client::Subscriber::open({.lcm_url = "udpm://10.0.0.1:7667"});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("not a multicast group"), std::string::npos);
}

TEST(EchoCommand, JsonLinesFromARealProcess) {
  std::atomic<bool> done{false};
  std::thread publisher([&] {
    lcm::LCM lcm(kUrl);
    for (std::int64_t seq = 0; !done; ++seq) {
      auto m = message("dev", "s", seq);
      lcm.publish(pose_channel("dev", "s"), &m);
      std::this_thread::sleep_for(5ms);
    }
  });
  const std::string cmd = std::string(COVTRACK_BINARY_DIR "/tools/covtrack/covtrack echo --json "
                                      "--count 5 --duration 10 --lcm-url '") + kUrl + "'";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::vector<nlohmann::json> lines;
  char buf[8192];
  while (fgets(buf, sizeof buf, p)) lines.push_back(nlohmann::json::parse(buf));
  const int status = pclose(p);
  done = true;
  publisher.join();
  EXPECT_EQ(WEXITSTATUS(status), 0);
  ASSERT_EQ(lines.size(), 5u);
  for (std::size_t i = 1; i < lines.size(); ++i)
    EXPECT_EQ(lines[i]["sequence"].get<std::int64_t>(), lines[i - 1]["sequence"].get<std::int64_t>() + 1);
  EXPECT_EQ(lines[0]["device"], "dev");
  EXPECT_EQ(lines[0]["covariance"].size(), 36u);
  EXPECT_NEAR(lines[0]["covariance"][0].get<double>(), 1e-6, 1e-18);
}
