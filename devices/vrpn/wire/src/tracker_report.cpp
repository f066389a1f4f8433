#include "covtrack/vrpn/tracker_report.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "covtrack/vrpn/byte_order.hpp"

namespace covtrack::vrpn {

std::vector<std::uint8_t> encode_pos_quat(const TrackerReport& r) {
  std::vector<std::uint8_t> out;
  out.reserve(kPosQuatSize);
  put_i32(out, r.sensor);
  put_i32(out, r.sensor);  // alignment, filled as VRPN fills it
  for (double v : r.position_m) put_f64(out, v);
  for (double v : r.quaternion_xyzw) put_f64(out, v);
  return out;
}

Result<TrackerReport> decode_pos_quat(std::span<const std::uint8_t> payload) {
  if (payload.size() != kPosQuatSize)
    return fail(fmt::format("VRPN tracker report of {} bytes ({} expected)", payload.size(), kPosQuatSize));
  TrackerReport r;
  r.sensor = get_i32(payload, 0);
  for (std::size_t i = 0; i < 3; ++i) r.position_m[i] = get_f64(payload, 8 + 8 * i);
  for (std::size_t i = 0; i < 4; ++i) r.quaternion_xyzw[i] = get_f64(payload, 32 + 8 * i);
  const auto finite = [](double v) { return std::isfinite(v); };
  if (!std::all_of(r.position_m.begin(), r.position_m.end(), finite) ||
      !std::all_of(r.quaternion_xyzw.begin(), r.quaternion_xyzw.end(), finite))
    return fail(fmt::format("VRPN tracker report of sensor {} holds a number that is not finite", r.sensor));
  const auto& q = r.quaternion_xyzw;
  if (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] < 1e-12)
    return fail(fmt::format("VRPN tracker report of sensor {} has a zero quaternion", r.sensor));
  return r;
}

TrackerReport report_of(std::int32_t sensor, const Pose& T) {
  const Eigen::Quaterniond q(T.rotation());
  const Vec3 t = T.translation();
  return {sensor, {t.x(), t.y(), t.z()}, {q.x(), q.y(), q.z(), q.w()}};
}

Pose pose_of(const TrackerReport& r) {
  const auto& q = r.quaternion_xyzw;
  return pose_from(Vec3(r.position_m[0], r.position_m[1], r.position_m[2]),
                   Eigen::Quaterniond(q[3], q[0], q[1], q[2]));
}

}  // namespace covtrack::vrpn
