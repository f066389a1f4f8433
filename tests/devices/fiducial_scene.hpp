#pragma once
// Shared by the fiducial tests: a small emulated camera and tag poses built from
// distance and angles.
#include <cmath>
#include <random>

#include "covtrack/emulators/fiducial/tag_image_formation.hpp"
#include "covtrack/protocol/camera_opencv.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::test {

// 320x240, about 60 degrees across: small frames keep the many detections fast.
inline Camera small_camera() {
  Camera c;
  c.width_px = 320, c.height_px = 240;
  c.fx = c.fy = 277.0;
  c.cx = 159.5, c.cy = 119.5;
  return c;
}

// A distortion-free camera of this size whose view spans `horizontal_fov_deg` across.
inline Camera camera(int width_px, int height_px, double horizontal_fov_deg) {
  Camera c;
  c.width_px = width_px, c.height_px = height_px;
  c.fx = c.fy = width_px / 2.0 / std::tan(horizontal_fov_deg * M_PI / 360);
  c.cx = (width_px - 1) / 2.0, c.cy = (height_px - 1) / 2.0;
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

// The camera population both sets draw from: tone curves from linear (gamma 1) to sRGB-like
// (2.4), Gaussian blur with or without a defocus disk, JPEG or none, vignetting, shot and
// read noise, print contrast (the corner model's calibration population:
// devices/fiducial/README.md, "Limits").
inline fiducial::ImageFormation random_formation(std::mt19937_64& rng, fiducial::Rasteriser rasteriser) {
  std::uniform_real_distribution<double> u(0, 1);
  const auto in = [&](double lo, double hi) { return lo + (hi - lo) * u(rng); };
  fiducial::ImageFormation f;
  f.rasteriser = rasteriser;
  f.gamma = in(1.0, 2.4);
  f.gauss_blur_px = in(0.4, 1.25);
  f.defocus_radius_px = u(rng) < 0.35 ? in(0.8, 1.4) : 0;
  f.jpeg_quality = u(rng) < 0.5 ? static_cast<int>(in(75, 97)) : 0;
  f.vignetting = in(0, 0.3);
  f.read_noise = in(1, 7);
  f.full_well_e = u(rng) < 0.5 ? in(3000, 8000) : 0;
  f.paper = in(0.7, 0.9), f.ink = in(0.03, 0.1), f.background = in(0.25, 0.6);
  if (rasteriser == fiducial::Rasteriser::JitteredPoints) {
    // Sensors whose light-sensitive part is 70-100% of the pixel pitch (fill factor).
    // Drawn from an engine of their own, seeded from a copy of rng, so that every other
    // draw of a set (the tags' poses) is the same whichever rasteriser it uses.
    std::mt19937_64 peek = rng;
    std::mt19937_64 own(peek() ^ 0x9e3779b97f4a7c15ULL);
    f.pixel_aperture = 0.7 + 0.3 * u(own);
    f.jitter_seed = own();
  }
  return f;
}

}  // namespace covtrack::test
