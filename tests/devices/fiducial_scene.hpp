#pragma once
// Shared by the fiducial tests: a small emulated camera and tag poses built from
// distance and angles.
#include <cmath>

#include "covtrack/devices/fiducial/camera_model.hpp"
#include "covtrack/devices/fiducial/corner_noise.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::test {

// 320x240, about 60 degrees across: small frames keep the many detections fast.
inline fiducial::CameraModel small_camera() {
  fiducial::CameraModel c;
  c.width_px = 320, c.height_px = 240;
  c.fx = c.fy = 277.0;
  c.cx = 159.5, c.cy = 119.5;
  return c;
}

// The tag `distance_m` ahead, offset sideways by (x, y) m, turned by yaw about its
// own vertical axis, pitch about its horizontal one and roll in its plane (degrees).
inline Pose tag_pose(double distance_m, double yaw_deg, double pitch_deg, double roll_deg,
                     double x_m = 0, double y_m = 0) {
  const double k = M_PI / 180;
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(roll_deg * k, Vec3::UnitZ()) *
                Eigen::AngleAxisd(yaw_deg * k, Vec3::UnitY()) *
                Eigen::AngleAxisd(pitch_deg * k, Vec3::UnitX())).toRotationMatrix();
  T.translation() = Vec3(x_m, y_m, distance_m);
  return T;
}

// The coefficients fiducial_nees_test calibrates (also the config defaults,
// devices/fiducial/src/fiducial_config.cpp).
inline fiducial::CornerNoiseModel calibrated_corner_model() {
  fiducial::CornerNoiseModel m;
  m.gain_px = 1.110, m.floor_px = 0.0295, m.aligned_px = 0.0864;
  m.radial_bias_px = 0.0056, m.radial_sigma_px = 0.0330;
  m.shift_px = 1.631, m.shift_falloff = 0.16, m.shift_sigma_px = 0.0952;
  return m;
}

}  // namespace covtrack::test
