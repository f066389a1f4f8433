#pragma once
// The keys that place a child frame in its parent in a config table: position_m, and
// the rotation as rotation_rpy_deg or orientation_wxyz (never both; neither: identity).
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack {

std::vector<KeySpec> pose_keys();

// T_parent_child from the table; problems (both rotations, a quaternion not of unit norm)
// go to the reader's errors and the identity rotation stands in.
Pose read_pose(TableReader& r);

// rotation_rpy_deg's rotation: R = Rz(yaw) Ry(pitch) Rx(roll), angles in degrees.
Mat3 rotation_from_rpy_deg(const Vec3& rpy_deg);

}  // namespace covtrack
