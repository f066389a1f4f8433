// The recorded Lenz session (tests/data/lenz_session.lcm, made by
// tools/record_lenz_session.sh) re-processed: the raw bytes the driver read are fed
// again through the decoder and the dead reckoning. The result must agree with the
// poses the driver published during the recording, and contain the recorded truth.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include <covtrack/pose_cov_t.hpp>
#include <covtrack/raw_bytes_t.hpp>
#include <covtrack/truth_pose_t.hpp>

#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/protocol/pose_message.hpp"
#include "dead_reckoning.hpp"
#include "layout_config.hpp"
#include "support/along_track.hpp"
#include "support/occupancy_replay.hpp"
#include "train_poses.hpp"

using namespace covtrack;
using namespace covtrack::lenz;

namespace {

template <class Msg>
bool decode(const lcmlog::LogEvent& e, Msg& msg) {
  return msg.decode(e.payload.data(), 0, static_cast<int>(e.payload.size())) >= 0;
}

// The driver's receive path without the port: raw bytes in, dead reckoning updated.
struct Reprocessor {
  explicit Reprocessor(const TrackLayout& layout) : replay(layout), reckoner(layout, {}) {}
  void feed(const raw_bytes_t& raw) {
    if (raw.direction != raw_bytes_t::FROM_DEVICE) return;
    replay.feed(raw.data, [&](const auto& occupied) { reckoner.on_occupancy(occupied, raw.time_us * 1e-6); });
  }
  test::OccupancyReplay replay;
  DeadReckoner reckoner;
};

}  // namespace

TEST(LenzSession, RawBytesReprocessedGiveTheRecordedPosesAndContainTheTruth) {
  auto layout = load_layout(COVTRACK_SOURCE_DIR "/config/lenz_layout.toml");
  ASSERT_TRUE(layout) << layout.error().message;
  auto log = lcmlog::LogReader::open(COVTRACK_SOURCE_DIR "/tests/data/lenz_session.lcm");
  ASSERT_TRUE(log) << log.error().message;

  Reprocessor first(*layout);
  std::vector<std::pair<std::int64_t, Pose>> truth;
  int compared = 0, agreeing = 0, degraded = 0;
  while (auto e = log->next()) {
    if (e->channel == "covtrack/raw/train") {
      raw_bytes_t raw;
      ASSERT_TRUE(decode(*e, raw));
      first.feed(raw);
    } else if (e->channel == "covtrack/truth/train/loco") {
      truth_pose_t t;
      ASSERT_TRUE(decode(*e, t));
      truth.emplace_back(t.measurement_time_us, pose_of(t));
    } else if (e->channel == "covtrack/pose/train/loco") {
      pose_cov_t p;
      ASSERT_TRUE(decode(*e, p));
      if (p.status != pose_cov_t::STATUS_DEGRADED) continue;
      ++degraded;
      const AlongTrack again = first.reckoner.estimate(p.measurement_time_us * 1e-6);
      if (again.state == AlongTrack::State::Lost) continue;
      ++compared;
      const Pose reprocessed = layout->pose_at(again.mid_s());
      const double sigma_recorded = std::sqrt(body_covariance_of(p)(0, 0));
      const double sigma_again = std::sqrt(vehicle_covariance(*layout, again.mid_s(), along_track_sigma(again, {}), {})(0, 0));
      // The driver stamped the bytes when it read them, the publisher a moment later.
      agreeing += (reprocessed.translation() - pose_of(p).translation()).norm() < 0.005 &&
                  std::abs(sigma_again - sigma_recorded) < 0.1 * sigma_recorded + 0.001;
    }
  }
  EXPECT_TRUE(log->damage().empty());
  ASSERT_GT(degraded, 150);
  ASSERT_GT(compared, 150);
  EXPECT_GE(double(agreeing) / compared, 0.95) << agreeing << " of " << compared;
  EXPECT_GT(first.replay.counters().frames, 30u);
  EXPECT_EQ(first.replay.counters().bad_frames, 0u);

  // Re-estimate at every recorded truth time: the truth inside the 99% interval.
  log->rewind();
  Reprocessor second(*layout);
  std::size_t next_truth = 0;
  int checked = 0, inside = 0;
  while (auto e = log->next()) {
    if (e->channel != "covtrack/raw/train") continue;
    raw_bytes_t raw;
    ASSERT_TRUE(decode(*e, raw));
    // Truth up to this moment, against the estimate made from the bytes before it.
    for (; next_truth < truth.size() && truth[next_truth].first < raw.time_us; ++next_truth) {
      const AlongTrack est = second.reckoner.estimate(truth[next_truth].first * 1e-6);
      if (est.state != AlongTrack::State::DeadReckoning) continue;
      ++checked;
      const double s_true = test::along_track_of(*layout, truth[next_truth].second.translation());
      inside += layout->wrap(s_true - est.lo_s) <= est.hi_s - est.lo_s + 0.001;
    }
    second.feed(raw);
  }
  ASSERT_GT(checked, 100);
  std::printf("session: %d of %d re-processed poses agree with the recording; truth inside the 99%% interval "
              "at %d of %d truth samples\n", agreeing, compared, inside, checked);
  EXPECT_GE(double(inside) / checked, 0.99);
}
