#include "covtrack/devices/pose_keys.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

namespace covtrack {

std::vector<KeySpec> pose_keys() {
  return {
      {"position_m", ValueType::FloatArray, "m", "[0, 0, 0]", "child origin in the parent frame", -1e6, 1e6, 3},
      {"rotation_rpy_deg", ValueType::FloatArray, "deg", "[0, 0, 0]",
       "roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll); or orientation_wxyz", -360, 360, 3},
      {"orientation_wxyz", ValueType::FloatArray, "", "(none)", "unit quaternion w x y z; instead of rotation_rpy_deg",
       -1, 1, 4},
  };
}

Pose read_pose(TableReader& r) {
  Pose T = Pose::Identity();
  T.translation() = r.vec3("position_m");
  if (r.has("orientation_wxyz") && r.has("rotation_rpy_deg")) {
    r.error("orientation_wxyz", "give orientation_wxyz or rotation_rpy_deg, not both");
  } else if (r.has("orientation_wxyz")) {
    const auto q = r.numbers("orientation_wxyz");
    if (q.size() == 4) {
      const Eigen::Quaterniond quat(q[0], q[1], q[2], q[3]);
      if (std::abs(quat.norm() - 1) > 1e-6)
        r.error("orientation_wxyz", fmt::format("norm is {}, not 1", quat.norm()));
      else
        T.linear() = quat.toRotationMatrix();
    }
  } else if (r.has("rotation_rpy_deg")) {
    T.linear() = rotation_from_rpy_deg(r.vec3("rotation_rpy_deg"));
  }
  return T;
}

Mat3 rotation_from_rpy_deg(const Vec3& rpy_deg) {
  const Vec3 rpy = rpy_deg * std::numbers::pi / 180;
  return (Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Vec3::UnitX())).toRotationMatrix();
}

}  // namespace covtrack
