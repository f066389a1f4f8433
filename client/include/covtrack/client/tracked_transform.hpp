#pragma once
// The latest report of one stream, as a plain value: what the transform graph binds to.
#include <cstdint>
#include <string>

#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/pose_message.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::client {

struct TrackedTransform {
  StreamId stream;
  std::string parent_frame;
  std::string child_frame;
  Pose T_parent_child = Pose::Identity();
  // BODY convention (protocol/README.md), whatever convention the message used. When
  // status is Lost it is meaningless (infinite uncertainty): check lost() first.
  Mat6 covariance = Mat6::Zero();
  TrackingStatus status = TrackingStatus::Lost;
  std::int64_t measurement_time_us = 0;
  std::int64_t publish_time_us = 0;
  std::int64_t receive_time_us = 0;
  std::int64_t sequence = 0;

  bool lost() const { return status == TrackingStatus::Lost; }
  // Seconds since the device measured the pose.
  double age_s(std::int64_t now_us) const { return 1e-6 * static_cast<double>(now_us - measurement_time_us); }
};

}  // namespace covtrack::client
