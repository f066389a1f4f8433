#pragma once
// The benchmarks' frame: boxes of 8 vertices scattered 1.5-3.5 m in front of the example
// camera, each with its own pose covariance (2-10 mm, 1-5 degrees). Same seed, same frame.
#include <cmath>
#include <random>
#include <vector>

#include "covtrack/client/regions.hpp"
#include "example_camera.hpp"

namespace covtrack::test {

struct BenchFrame {
  client::Camera camera = example_camera();
  std::vector<client::UncertainPose> poses;
  std::vector<std::vector<Vec3>> vertices;
};

inline BenchFrame make_bench_frame(int objects) {
  BenchFrame f;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < objects; ++i) {
    const Vec3 t(0.8 * u(rng), 0.6 * u(rng), 2.5 + u(rng));
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    Vec6 d;
    d << Vec3::Constant(std::pow(0.002 + 0.004 * (u(rng) + 1), 2)),
        Vec3::Constant(std::pow((1 + 2 * (u(rng) + 1)) * 3.14159 / 180, 2));
    f.poses.push_back({pose_from(t, Eigen::Quaterniond(Eigen::AngleAxisd(3 * u(rng), axis))),
                       d.asDiagonal(), false});
    std::vector<Vec3> box;
    const double s = 0.1 + 0.05 * u(rng);
    for (int k = 0; k < 8; ++k)
      box.emplace_back(k & 1 ? s : -s, k & 2 ? 0.7 * s : -0.7 * s, k & 4 ? 0.5 * s : -0.5 * s);
    f.vertices.push_back(box);
  }
  return f;
}

}  // namespace covtrack::test
