#pragma once
// Sampled poses and covariances for the transform graph's tests: every expected value is
// drawn, never typed in.
#include <cmath>
#include <functional>
#include <random>

#include "covtrack/client/tracked_transform.hpp"
#include "covtrack/client/uncertain_pose.hpp"

namespace covtrack::client::test {

constexpr double kDeg = M_PI / 180.0;
constexpr std::int64_t kT0 = 1'700'000'000'000'000;  // a measurement time, us

// A full (correlated) covariance with the given translation and rotation sigmas, so that
// a transposed Jacobian or a swapped block shows.
inline Mat6 covariance(double sigma_m, double sigma_rad, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n;
  Mat6 A;
  for (int i = 0; i < 36; ++i) A(i) = n(rng);
  Mat6 corr = A * A.transpose() + 3.0 * Mat6::Identity();
  const Vec6 d = corr.diagonal().cwiseSqrt().cwiseInverse();
  corr = d.asDiagonal() * corr * d.asDiagonal();
  Vec6 s;
  s << Vec3::Constant(sigma_m), Vec3::Constant(sigma_rad);
  return s.asDiagonal() * corr * s.asDiagonal();
}

inline Pose pose(double x, double y, double z, double rx, double ry, double rz) {
  Vec6 xi;
  xi << x, y, z, rx, ry, rz;
  Pose T = Pose::Identity();
  T.linear() = so3_exp(xi.tail<3>());
  T.translation() = xi.head<3>();
  return T;
}

inline double relative_frobenius(const Mat6& estimate, const Mat6& reference) {
  return (estimate - reference).norm() / reference.norm();
}

// Draws T (+) xi with xi ~ N(0, C).
struct Sampler {
  Pose T;
  Eigen::Matrix<double, 6, 6> L;
  Sampler(const Pose& T_, const Mat6& C) : T(T_), L(C.llt().matrixL()) {}
  Pose operator()(std::mt19937& rng) const {
    std::normal_distribution<double> n;
    Vec6 z;
    for (int i = 0; i < 6; ++i) z(i) = n(rng);
    return boxplus(T, L * z);
  }
};

// E[(sample (-) mean)(sample (-) mean)^T] over n draws of `sample`.
inline Mat6 monte_carlo(const Pose& mean, const std::function<Pose(std::mt19937&)>& sample, int n = 100'000) {
  std::mt19937 rng(42);
  Mat6 acc = Mat6::Zero();
  for (int i = 0; i < n; ++i) {
    const Vec6 e = boxminus(sample(rng), mean);
    acc += e * e.transpose();
  }
  return acc / n;
}

inline TrackedTransform report(const StreamId& id, const Pose& T, const Mat6& C, std::int64_t time_us,
                        TrackingStatus status = TrackingStatus::Ok) {
  TrackedTransform t;
  t.stream = id;
  t.T_parent_child = T;
  t.covariance = C;
  t.status = status;
  t.measurement_time_us = time_us;
  return t;
}

}  // namespace covtrack::client::test
