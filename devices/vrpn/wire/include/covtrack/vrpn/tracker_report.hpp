#pragma once
// The payload of a "vrpn_Tracker Pos_Quat" message and its conversion from and to a
// covtrack pose (docs/vrpn.md, "Tracker reports").
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::vrpn {

// 64 bytes: the sensor number as a big-endian 32-bit integer, written twice (the
// second only aligns what follows to 8 bytes), then seven big-endian doubles.
inline constexpr std::size_t kPosQuatSize = 64;

// VRPN's conventions: T_source_sensor (the sensor's pose in the tracker's frame, as
// covtrack's T_parent_child), position in metres, the unit quaternion in the order
// x, y, z, w (covtrack's messages use w, x, y, z).
struct TrackerReport {
  std::int32_t sensor = 0;
  std::array<double, 3> position_m{};
  std::array<double, 4> quaternion_xyzw{0, 0, 0, 1};
};

std::vector<std::uint8_t> encode_pos_quat(const TrackerReport& report);
// Checks the size and that every number is finite and the quaternion not zero; a
// quaternion of any other length is accepted (pose_of normalises it).
Result<TrackerReport> decode_pos_quat(std::span<const std::uint8_t> payload);

TrackerReport report_of(std::int32_t sensor, const Pose& T_source_sensor);
Pose pose_of(const TrackerReport& report);

}  // namespace covtrack::vrpn
