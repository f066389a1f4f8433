// Whole-object containment of the outer region, by Monte Carlo: poses drawn from the
// covariance, the whole object projected (its vertices and points along its edges), and
// the fraction of draws with all of it inside the outer region must reach the confidence,
// less the binomial 99% tolerance. Also reported: how many draws the older per-vertex
// scale held, and the outer region's area against the smallest convex region holding the
// object with that probability (the support-quantile bound) and, for a point, against its
// ellipse.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "example_camera.hpp"

#include "covtrack/client/regions.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kDraws = 20000;
constexpr double kConfidences[] = {0.68, 0.95, 0.99};
constexpr int kPointsPerEdge = 8;  // along each edge, ends included

struct Shape {
  std::string name;
  std::vector<Vec3> vertices;
  std::vector<std::pair<int, int>> edges;
};

Shape box(std::string name, double sx, double sy, double sz) {
  Shape s{std::move(name), {}, {}};
  for (int i = 0; i < 8; ++i)
    s.vertices.emplace_back((i & 1 ? 0.5 : -0.5) * sx, (i & 2 ? 0.5 : -0.5) * sy, (i & 4 ? 0.5 : -0.5) * sz);
  for (int i = 0; i < 8; ++i)
    for (int bit : {1, 2, 4})
      if (!(i & bit)) s.edges.emplace_back(i, i | bit);
  return s;
}

// Every point whose pixel must be inside: vertices and points along the edges.
std::vector<Vec3> object_points(const Shape& s) {
  std::vector<Vec3> points = s.vertices;
  for (auto [a, b] : s.edges)
    for (int k = 1; k < kPointsPerEdge - 1; ++k) {
      const double t = double(k) / (kPointsPerEdge - 1);
      points.push_back((1 - t) * s.vertices[a] + t * s.vertices[b]);
    }
  return points;
}

// A correlated covariance: marginal sigmas (translation, rotation) and a random correlation.
Mat6 correlated_covariance(double translation_sigma_m, double rotation_sigma_rad, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Mat6 B;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) B(i, j) = normal(rng);
  Mat6 R = B * B.transpose() + 2 * Mat6::Identity();  // well conditioned, clearly correlated
  const Vec6 d = R.diagonal().cwiseSqrt().cwiseInverse();
  R = d.asDiagonal() * R * d.asDiagonal();
  Vec6 sigma;
  sigma << Vec3::Constant(translation_sigma_m), Vec3::Constant(rotation_sigma_rad);
  return sigma.asDiagonal() * R * sigma.asDiagonal();
}

Camera pinhole() {
  Camera c = test::example_camera();
  c.k1 = c.k2 = c.p1 = c.p2 = c.k3 = 0;
  return c;
}

// The smallest convex region holding the points with probability p contains, for every
// direction n, the half-plane up to the p-quantile of max_i n . x_i (else the object would
// cross that line in more than 1 - p of the draws): their intersection is a lower bound.
double support_quantile_area(const std::vector<std::vector<Vec2>>& draws, double p) {
  constexpr int kDirections = 180;
  Polygon region;
  Eigen::AlignedBox2d box;
  for (const auto& d : draws)
    for (const Vec2& x : d) box.extend(x);
  region = {box.min(), Vec2(box.max().x(), box.min().y()), box.max(), Vec2(box.min().x(), box.max().y())};
  std::vector<double> supports(draws.size());
  for (int k = 0; k < kDirections; ++k) {
    const double a = 2 * std::numbers::pi * k / kDirections;
    const Vec2 n(std::cos(a), std::sin(a));
    for (std::size_t s = 0; s < draws.size(); ++s) {
      double top = -std::numeric_limits<double>::infinity();
      for (const Vec2& x : draws[s]) top = std::max(top, n.dot(x));
      supports[s] = top;
    }
    const std::size_t q = std::min(draws.size() - 1, static_cast<std::size_t>(std::ceil(p * draws.size())));
    std::nth_element(supports.begin(), supports.begin() + q, supports.end());
    region = clip_half_plane(region, n, supports[q]);
  }
  return polygon_area(region);
}

// Pixels of the points under `draws` poses drawn from the pose's covariance (T Exp(xi)).
std::vector<std::vector<Vec2>> draw_pixels(const Camera& camera, const UncertainPose& pose,
                                           std::span<const Vec3> points, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  const Mat6 L = Eigen::LLT<Mat6>(pose.covariance).matrixL();
  std::vector<std::vector<Vec2>> draws(kDraws);
  for (auto& pixels : draws) {
    Vec6 z;
    for (int k = 0; k < 6; ++k) z[k] = normal(rng);
    const Pose T = pose.T * se3_exp(L * z);
    for (const Vec3& p : points) pixels.push_back(camera.project(T * p));
    pixels = convex_hull(pixels);  // inside a convex region iff its hull is; and quicker
  }
  return draws;
}

struct Scene {
  std::string camera_name;
  Camera camera;
  Shape shape;
  Vec3 position_m;
  double translation_sigma_m, rotation_sigma_rad;
};

void check_containment(const Scene& scene, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const UncertainPose pose{
      pose_from(scene.position_m, Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized()))),
      correlated_covariance(scene.translation_sigma_m, scene.rotation_sigma_rad, rng), false};
  const std::vector<Vec3> points = object_points(scene.shape);
  ObjectRegionOptions whole, per_vertex;
  whole.projection.add_intrinsic_uncertainty = per_vertex.projection.add_intrinsic_uncertainty = false;
  per_vertex.regions.whole_object = false;

  // The same draws for every confidence.
  const std::vector<std::vector<Vec2>> draws = draw_pixels(scene.camera, pose, points, rng);
  const auto fraction_inside = [&](const Polygon& region) {
    int inside = 0;
    for (const auto& pixels : draws)
      inside += std::all_of(pixels.begin(), pixels.end(), [&](const Vec2& x) { return polygon_contains(region, x, 0); });
    return double(inside) / kDraws;
  };

  for (double p : kConfidences) {
    whole.regions.confidence = per_vertex.regions.confidence = p;
    const ObjectRegions r = compute_object_regions(scene.camera, pose, scene.shape.vertices, whole);
    const ObjectRegions old = compute_object_regions(scene.camera, pose, scene.shape.vertices, per_vertex);
    ASSERT_TRUE(r.valid) << scene.shape.name;
    const double held = fraction_inside(r.outer), held_before = fraction_inside(old.outer);
    // Binomial 99% (one-sided, normal approximation): a region holding the object with
    // probability exactly p falls below this in 1% of such runs.
    const double tolerance = 2.326 * std::sqrt(p * (1 - p) / kDraws);
    const double best = support_quantile_area(draws, p);
    const double area = polygon_area(r.outer);
    std::printf("%-8s %-7s rot %4.1f deg  p %.2f: whole object held %.4f (per-vertex scale %.4f), scale %.2f "
                "(per vertex %.2f), area %.0f px^2 = %.2fx the support-quantile bound (per-vertex %.2fx)%s\n",
                scene.camera_name.c_str(), scene.shape.name.c_str(), scene.rotation_sigma_rad / kDeg, p, held,
                held_before, r.outer_scale, old.outer_scale, area, area / best, polygon_area(old.outer) / best,
                r.flags.depth_nonlinear ? " [depth_nonlinear]" : "");
    EXPECT_GE(held, p - tolerance) << scene.camera_name << " " << scene.shape.name << " rotation sigma "
                                   << scene.rotation_sigma_rad / kDeg << " deg, p " << p;
  }
}

std::vector<Scene> scenes() {
  const Shape small = box("small", 0.06, 0.04, 0.03), large = box("large", 0.6, 0.4, 0.3),
              stylus = box("stylus", 0.3, 0.012, 0.012);
  std::vector<Scene> out;
  for (const auto& [name, camera] : {std::pair{std::string("lens"), test::example_camera()},
                                     std::pair{std::string("pinhole"), pinhole()}})
    for (double rotation_deg : {2.0, 5.0, 10.0, 20.0}) {
      out.push_back({name, camera, small, Vec3(0.05, -0.03, 0.8), 0.003, rotation_deg * kDeg});
      out.push_back({name, camera, large, Vec3(-0.1, 0.05, 2.5), 0.01, rotation_deg * kDeg});
      out.push_back({name, camera, stylus, Vec3(0.1, 0.1, 1.2), 0.004, rotation_deg * kDeg});
    }
  return out;
}

}  // namespace

TEST(WholeObjectContainment, OuterRegionHoldsTheWholeObjectAtItsConfidence) {
  std::uint64_t seed = 1;
  for (const Scene& s : scenes()) check_containment(s, seed++);
}

// A point: the best convex region is its ellipse, so the support-quantile bound is out of
// reach (the ellipse is chi2_2(p) / z_p^2 times its area); both ratios are reported.
TEST(WholeObjectContainment, PointObjectAgainstItsEllipseAndTheSupportBound) {
  std::mt19937_64 rng(77);
  const Camera camera = test::example_camera();
  const UncertainPose pose{pose_from(Vec3(0.05, 0, 1.0), Eigen::Quaterniond::Identity()),
                           correlated_covariance(0.004, 3 * kDeg, rng), false};
  const std::vector<Vec3> point = {Vec3(0.02, 0.01, 0)};
  const std::vector<std::vector<Vec2>> draws = draw_pixels(camera, pose, point, rng);
  for (double p : kConfidences) {
    ObjectRegionOptions o;
    o.projection.add_intrinsic_uncertainty = false;
    o.regions.confidence = p;
    const ObjectRegions r = compute_object_regions(camera, pose, point, o);
    ASSERT_TRUE(r.valid);
    int inside = 0;
    for (const auto& d : draws) inside += polygon_contains(r.outer, d[0], 0);
    const double held = double(inside) / kDraws, area = polygon_area(r.outer);
    const double ellipse = std::numbers::pi * -2 * std::log1p(-p) * std::sqrt(r.vertices[0].covariance_px2.determinant());
    std::printf("point p %.2f: held %.4f, area %.1f px^2 = %.2fx its p-ellipse, %.2fx the support-quantile bound\n",
                p, held, area, area / ellipse, area / support_quantile_area(draws, p));
    EXPECT_GE(held, p - 2.326 * std::sqrt(p * (1 - p) / kDraws));
    EXPECT_NEAR(r.outer_scale * r.outer_scale, -2 * std::log1p(-p), 1e-9);  // a point's own quantile
  }
}
