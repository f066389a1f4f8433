// The race rule on its own: two claimants (publishing on one LCM instance, each listening
// through its own filtered socket) whose claim waits run side by side over real UDP
// multicast (inside this test's network namespace), 2 s each, so that each hears the other
// only as a claimant, never as a holder. Exactly one keeps the device: the earlier claim.
// And a holder answers a later claimant at once.
#include <gtest/gtest.h>

#include <future>
#include <thread>

#include "device_ownership.hpp"

using namespace covtrack::server;
using namespace std::chrono_literals;

namespace {

const std::string kUrl = "udpm://239.255.76.67:7736?ttl=0";

PublisherIdentity identity(std::int64_t id, std::int32_t pid) { return {id, "testhost", pid}; }

// The claim wait itself (what the daemon spends in sigtimedwait): nothing to wait for.
bool wait_out(std::chrono::milliseconds t) {
  std::this_thread::sleep_for(t);
  return true;
}

DeviceOwnership::GiveUp no_give_up() {
  return [](const std::string& device, const std::string& why) {
    ADD_FAILURE() << "gave up " << device << ": " << why;
  };
}

}  // namespace

TEST(OwnershipRace, TwoClaimsAtOnceLeaveTheDeviceToTheEarlierClaim) {
  lcm::LCM lcm(kUrl);
  ASSERT_TRUE(lcm.good());
  // Opened one after the other: a's claimed_us is the smaller (or equal, then the ids
  // decide, and 1 < 2 as well).
  auto a = DeviceOwnership::open(lcm, kUrl, identity(1, 101), {"rig", "other_a"}, {.wait_s = 2}, no_give_up());
  auto b = DeviceOwnership::open(lcm, kUrl, identity(2, 202), {"rig", "other_b"}, {.wait_s = 2}, no_give_up());
  ASSERT_TRUE(a && b);

  auto claim_a = std::async(std::launch::async, [&] { return (*a)->claim(wait_out); });
  auto claim_b = std::async(std::launch::async, [&] { return (*b)->claim(wait_out); });
  const auto refused_a = claim_a.get();
  const auto refused_b = claim_b.get();
  ASSERT_TRUE(refused_a && refused_b);

  EXPECT_TRUE(refused_a->empty()) << refused_a->begin()->second;
  ASSERT_EQ(refused_b->size(), 1u);  // "other_b" is b's alone
  ASSERT_TRUE(refused_b->contains("rig"));
  const std::string& why = refused_b->at("rig");
  EXPECT_NE(why.find("covtrackd on testhost/101 (instance 0000000000000001)"), std::string::npos) << why;
  EXPECT_NE(why.find("claimed it at the same time and comes first"), std::string::npos) << why;
}

TEST(OwnershipRace, AHolderAnswersALaterClaimantAtOnce) {
  lcm::LCM lcm(kUrl);
  ASSERT_TRUE(lcm.good());
  auto a = DeviceOwnership::open(lcm, kUrl, identity(9, 909), {"rig"}, {.wait_s = 0}, no_give_up());
  ASSERT_TRUE(a);
  ASSERT_TRUE((*a)->claim(wait_out));  // no wait: holds at once, and sends no heartbeat here

  auto b = DeviceOwnership::open(lcm, kUrl, identity(3, 303), {"rig"}, {.wait_s = 0.5}, no_give_up());
  ASSERT_TRUE(b);
  const auto refused = (*b)->claim(wait_out);
  ASSERT_TRUE(refused);
  ASSERT_TRUE(refused->contains("rig"));
  // Refused for the holder, even though b's instance id is the smaller.
  EXPECT_NE(refused->at("rig").find("covtrackd on testhost/909 (instance 0000000000000009) already publishes it"),
            std::string::npos)
      << refused->at("rig");
}
