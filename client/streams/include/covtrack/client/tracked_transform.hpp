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
  Pose T_parent_child = Pose::Identity();  // maps child coordinates into the parent frame
  // BODY convention (T_true = T * Exp(xi), xi = [translation, rotation], m^2 / rad^2),
  // whatever convention the message used on the wire.
  //
  // When status is Lost the tracker is not reporting: pose and covariance carry no
  // information and the transform must be treated as infinitely uncertain. The
  // covariance is then +infinity on the diagonal and 0 elsewhere (never NaN) so that
  // arithmetic on it stays infinite; check lost() rather than reading it.
  Mat6 covariance = Mat6::Zero();
  TrackingStatus status = TrackingStatus::Lost;
  std::int64_t measurement_time_us = 0;  // CLOCK_REALTIME, when the device measured
  std::int64_t publish_time_us = 0;      // when the daemon published
  std::int64_t receive_time_us = 0;      // when this client decoded it
  std::int64_t sequence = 0;             // per stream, +1 per message, 0 after a daemon restart
  // Not from the wire: the client reports the stream LOST (with its last pose, time and
  // sequence) because its device's heartbeat stopped (DeviceTracker): the daemon is gone.
  bool device_unreachable = false;

  bool lost() const { return status == TrackingStatus::Lost; }
  // Seconds since the device measured the pose (now_us from covtrack::now_us()).
  double age_s(std::int64_t now_us) const { return 1e-6 * static_cast<double>(now_us - measurement_time_us); }
};

}  // namespace covtrack::client
