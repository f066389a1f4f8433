// Camera calibration files (OpenCV's YAML or XML, ROS's camera_info YAML): the input
// written to a file whose name says neither, so that load_camera picks the syntax by the
// first character as for any such name, and loaded as the daemon's fiducial driver,
// `covtrack view` and `covtrack ar` load one. A camera that loads has a sane size, a
// pinhole matrix and finite numbers, and projects a point ahead of it onto finite pixels
// with a finite intrinsic covariance.
#include <cmath>

#include "covtrack/protocol/camera.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace covtrack;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static fuzz::ScratchFile file(".calib");
  const std::string& path = file.write({data, size});
  const auto camera = load_camera(path);
  if (!camera) {
    FUZZ_CHECK(camera.error().message.starts_with(path + ": "));
    return 0;
  }
  const Camera& c = *camera;
  FUZZ_CHECK(c.width_px > 0 && c.width_px <= 16384 && c.height_px > 0 && c.height_px <= 16384);
  FUZZ_CHECK(c.fx > 0 && c.fy > 0 && fuzz::finite(c.fx) && fuzz::finite(c.fy));
  FUZZ_CHECK(fuzz::finite(c.cx) && fuzz::finite(c.cy));
  for (const double k : {c.k1, c.k2, c.p1, c.p2, c.k3}) FUZZ_CHECK(fuzz::finite(k));
  FUZZ_CHECK(c.intrinsic_sigmas_px.allFinite() && (c.intrinsic_sigmas_px.array() >= 0).all());
  FUZZ_CHECK((c.project(Vec3(0, 0, 1)) - Vec2(c.cx, c.cy)).norm() <= 1e-9 * (1 + std::abs(c.cx) + std::abs(c.cy)));
  FUZZ_CHECK(c.intrinsic_covariance(Vec3(0.01, -0.02, 1)).allFinite());
  return 0;
}
