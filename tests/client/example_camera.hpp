#pragma once
// The camera of config/cameras/example_640x480.yml, distortion included, for tests that
// should not depend on reading the file.
#include "covtrack/client/camera.hpp"

namespace covtrack::test {

inline client::Camera example_camera() {
  client::Camera c;
  c.fx = 552.31, c.fy = 551.08, c.cx = 318.74, c.cy = 243.52;
  c.width_px = 640, c.height_px = 480;
  c.k1 = -0.04127, c.k2 = 0.1834, c.p1 = 6.1e-4, c.p2 = -3.2e-4, c.k3 = -0.2915;
  return c;
}

}  // namespace covtrack::test
