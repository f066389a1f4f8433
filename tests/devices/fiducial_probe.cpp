#include <cstdio>
#include "covtrack/devices/fiducial/noise_calibration.hpp"
#include "fiducial_scene.hpp"
using namespace covtrack; using namespace covtrack::fiducial;
int main(int argc, char** argv) {
  const CameraModel cam = test::small_camera();
  DetectorOptions o; o.decimate = 1;
  auto run = [&](double yaw, double roll, double noise, double size, double dist) {
    CalibrationView v; v.tag = {1, size, test::tag_pose(dist, yaw, 3, roll, 0.01, 0.01)}; v.noise_sigma = noise;
    auto d = draw_view(cam, o, v, 40, 5);
    double sq = 0, x = 0; int n = 0; double edge=0;
    for (auto& r : *d) if (r.detection) { sq += r.corner_sq_error_px2; x += CornerNoiseModel::noise_term(r.image_noise, r.contrast, r.edge_length_px); edge += r.edge_length_px; ++n; }
    std::printf("yaw %4.0f roll %4.0f noise %4.1f size %.2f edge %5.1f rms %.3f noiseterm^.5*1.34 %.3f\n", yaw, roll, noise, size, edge/n, std::sqrt(sq/n), 1.344*std::sqrt(x/n));
  };
  for (double roll : {0., 2., 5., 10., 20., 30., 45.}) run(10, roll, 0.5, 0.16, 0.8);
  for (double yaw : {0., 20., 40., 50., 60.}) run(yaw, 30, 0.5, 0.16, 0.8);
  for (double yaw : {0., 20., 40., 50., 60.}) run(yaw, 30, 5, 0.16, 0.8);
}
