#pragma once
// Valid pose messages for the client tests and benchmarks.
#include <cstdint>
#include <string>
#include <vector>

#include <covtrack/pose_cov_t.hpp>

#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/pose_message.hpp"

namespace covtrack::test {

// Correlated, positive definite, not diagonal: a conversion error would show.
inline Mat6 test_covariance() {
  Mat6 c = Mat6::Zero();
  c.diagonal() << 1e-6, 2e-6, 3e-6, 1e-5, 2e-5, 3e-5;
  c(0, 1) = c(1, 0) = 5e-7;
  c(2, 4) = c(4, 2) = 1e-6;
  return c;
}

inline Pose test_pose() {
  Pose T = Pose::Identity();
  T.linear() = so3_exp(Vec3(0.1, 0.2, 0.3));
  T.translation() = Vec3(1, 2, 3);
  return T;
}

inline pose_cov_t pose_message(const std::string& device, const std::string& sensor,
                               std::int64_t sequence) {
  pose_cov_t m{};
  m.device = device;
  m.sensor = sensor;
  m.parent_frame = "world";
  m.child_frame = sensor;
  m.sequence = sequence;
  m.measurement_time_us = m.publish_time_us = now_us();
  m.status = pose_cov_t::STATUS_OK;
  set_pose(m, test_pose(), test_covariance());
  return m;
}

// The message as LCM encodes it (what a publisher sends, before any trailer).
template <typename Msg>
std::vector<std::uint8_t> encoded(const Msg& m) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(out.data(), 0, static_cast<int>(out.size()));
  return out;
}

}  // namespace covtrack::test
