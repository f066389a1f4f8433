// Sequence numbers classified: loss within the window, forged and duplicate numbers off
// the track, restarts followed once the new sequence carries on alone, two publishers.
#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "covtrack/client/sequence_tracker.hpp"

using covtrack::client::SequenceTracker;
using V = SequenceTracker::Verdict;

namespace {

struct Tally {
  std::int64_t delivered = 0, lost = 0, foreign = 0, restarts = 0;
};

Tally run(SequenceTracker& t, const std::vector<std::int64_t>& sequence) {
  Tally tally;
  for (std::int64_t s : sequence) {
    const auto r = t.classify(s);
    tally.lost += r.lost;
    tally.restarts += r.verdict == V::Restart;
    if (r.verdict == V::Foreign) ++tally.foreign;
    else ++tally.delivered;
  }
  return tally;
}

}  // namespace

TEST(SequenceTracker, GapsWithinTheWindowAreLoss) {
  SequenceTracker t(1000);
  const Tally r = run(t, {5, 6, 9, 1009, 1010});  // 7, 8 and 999 numbers lost
  EXPECT_EQ(r.delivered, 5);
  EXPECT_EQ(r.lost, 2 + 999);
  EXPECT_EQ(r.foreign, 0);
}

TEST(SequenceTracker, ForgedFarAheadOrBehindIsForeignAndLossStaysTrue) {
  SequenceTracker t(1000);
  const std::int64_t max = std::numeric_limits<std::int64_t>::max(), min = std::numeric_limits<std::int64_t>::min();
  const Tally r = run(t, {10, 11, 670'000'000'000'000'000, 12, max, min, 13, 13 + 1001, 14, 11, 15});
  EXPECT_EQ(r.lost, 0);
  EXPECT_EQ(r.foreign, 5);  // three forged, one 1001 ahead (past the window), a duplicate
  EXPECT_EQ(r.restarts, 0);
  EXPECT_EQ(r.delivered, 6);
}

TEST(SequenceTracker, RestartIsFollowedOnceTheNewSequenceCarriesOnAlone) {
  SequenceTracker t(50);
  const Tally before = run(t, {100, 101, 102});
  EXPECT_EQ(before.delivered, 3);
  // The daemon restarted: 0 and 1 cannot yet be told from a second publisher's.
  EXPECT_EQ(t.classify(0).verdict, V::Foreign);
  EXPECT_EQ(t.classify(1).verdict, V::Foreign);
  static_assert(SequenceTracker::kConfirm == 3);
  EXPECT_EQ(t.classify(2).verdict, V::Restart);
  const auto next = t.classify(4);
  EXPECT_EQ(next.verdict, V::InOrder);
  EXPECT_EQ(next.lost, 1);
  EXPECT_EQ(t.classify(103).verdict, V::Foreign);  // the old sequence is no longer the stream's
}

TEST(SequenceTracker, LossLongerThanTheWindowIsARestartNotLoss) {
  SequenceTracker t(1000);
  const Tally r = run(t, {0, 1, 5000, 5001, 5002, 5003});
  EXPECT_EQ(r.restarts, 1);
  EXPECT_EQ(r.lost, 0);
  EXPECT_EQ(r.foreign, SequenceTracker::kConfirm - 1);
  EXPECT_EQ(r.delivered, 4);
}

TEST(SequenceTracker, SecondPublisherInterleavedIsForeignAndNeverTakesOver) {
  SequenceTracker t(1000);
  std::vector<std::int64_t> interleaved;
  for (std::int64_t k = 0; k < 50; ++k) interleaved.insert(interleaved.end(), {1000 + k, k, k + 1});  // it sends 2 for 1
  const Tally r = run(t, interleaved);
  EXPECT_EQ(r.delivered, 50);
  EXPECT_EQ(r.foreign, 100);
  EXPECT_EQ(r.lost, 0);
  EXPECT_EQ(r.restarts, 0);
}
