// Ellipse polygons, hulls, expansion and contraction, assessment, honesty on Monte Carlo.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <fmt/format.h>

#include "angle_bound.hpp"
#include "bench_frame.hpp"
#include "example_camera.hpp"

#include "covtrack/client/regions.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::vector<Vec3> box_vertices(double sx, double sy, double sz) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i)
    v.emplace_back((i & 1 ? 0.5 : -0.5) * sx, (i & 2 ? 0.5 : -0.5) * sy, (i & 4 ? 0.5 : -0.5) * sz);
  return v;
}

UncertainPose box_pose(double translation_sigma_m, double rotation_sigma_rad) {
  Vec6 d;
  d << Vec3::Constant(std::pow(translation_sigma_m, 2)), Vec3::Constant(std::pow(rotation_sigma_rad, 2));
  return {pose_from(Vec3(0.1, 0.05, 1.5),
                    Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Vec3(1, 2, 0.5).normalized()))),
          d.asDiagonal(), false};
}

Mat2 random_covariance(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Mat2 B;
  B << 5 * u(rng), 5 * u(rng), 5 * u(rng), 5 * u(rng);
  return B * B.transpose() + 0.01 * Mat2::Identity();
}

}  // namespace

TEST(EllipsePolygon, ContainsTheEllipseWithinTheDocumentedBound) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const Mat2 C = random_covariance(rng);
    const Vec2 c(100 + trial, 50 - trial);
    const double scale = confidence_scale(0.95);
    const int sides = 8 + trial % 20;
    const Polygon poly = circumscribed_ellipse_polygon(c, C, scale, sides);
    ASSERT_EQ(static_cast<int>(poly.size()), sides);
    ASSERT_GT(polygon_area(poly), 0) << "counter-clockwise";
    const Mat2 L = Eigen::LLT<Mat2>(C).matrixL();
    std::vector<Vec2> boundary;
    for (int k = 0; k < 4000; ++k) {
      const double t = 2 * std::numbers::pi * k / 4000;
      boundary.push_back(c + scale * L * Vec2(std::cos(t), std::sin(t)));
      ASSERT_TRUE(polygon_contains(poly, boundary.back(), 1e-9)) << "trial " << trial;
    }
    const double a = scale * ellipse_axes(C).major_px;
    const double bound = a * (1 / std::cos(std::numbers::pi / sides) - 1);
    for (const Vec2& vertex : poly) {
      double nearest = 1e300;
      for (const Vec2& b : boundary) nearest = std::min(nearest, (vertex - b).norm());
      EXPECT_LE(nearest, bound * 1.0001 + 1e-3) << "trial " << trial;
    }
  }
}

TEST(EllipsePolygon, SideCountMeetsTheToleranceAndNoMore) {
  for (double a : {1.0, 10.0, 100.0, 1000.0}) {
    const int n = circumscribed_polygon_sides(a, 0.5, 3, 100000);
    EXPECT_LE(a * (1 / std::cos(std::numbers::pi / n) - 1), 0.5) << a;
    if (n > 3) {
      EXPECT_GT(a * (1 / std::cos(std::numbers::pi / (n - 1)) - 1), 0.5) << a;
    }
  }
  EXPECT_EQ(circumscribed_polygon_sides(1e6, 0.5, 8, 64), 64);  // the cap
  EXPECT_EQ(circumscribed_polygon_sides(0.0, 0.5, 8, 64), 8);
}

TEST(ConvexHull, MonotoneChainDropsInteriorAndCollinearPoints) {
  const std::vector<Vec2> pts = {{0, 0}, {2, 0}, {1, 0}, {2, 2}, {0, 2}, {1, 1}, {0.5, 1.5}, {2, 1}};
  const Polygon h = convex_hull(pts);
  ASSERT_EQ(h.size(), 4u);
  EXPECT_DOUBLE_EQ(polygon_area(h), 4.0);
  for (const Vec2& p : pts) EXPECT_TRUE(polygon_contains(h, p, 1e-12));
  EXPECT_FALSE(polygon_contains(h, Vec2(2.1, 1), 1e-12));
}

TEST(ConvexHull, PrefilteredHullEqualsPlainMonotoneChain) {
  // convex_hull drops points inside an 8-direction extreme polygon first (> 32 points);
  // convex_hull_indices does not. Both must give the same polygon.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0, 50);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Vec2> pts;
    for (int i = 0; i < 40 + 30 * trial; ++i) pts.emplace_back(g(rng), 0.3 * g(rng));
    const Polygon fast = convex_hull(pts);
    Polygon plain;
    for (int i : convex_hull_indices(pts)) plain.push_back(pts[i]);
    ASSERT_EQ(fast.size(), plain.size()) << "trial " << trial;
    for (std::size_t i = 0; i < fast.size(); ++i) EXPECT_EQ(fast[i], plain[i]);
    for (const Vec2& p : pts) EXPECT_TRUE(polygon_contains(fast, p, 1e-9));
  }
}

// What a hull from convex_hull_indices must be, checked without either of its paths: it
// starts at the lowest x (then y), turns strictly left at every vertex (no point in line,
// no repeat), and has every point inside or on it.
void expect_is_the_hull(std::span<const Vec2> pts, const std::vector<int>& hull, int trial) {
  ASSERT_GE(hull.size(), 1u) << "trial " << trial;
  for (const Vec2& p : pts) {
    const Vec2& s = pts[hull[0]];
    ASSERT_TRUE(s.x() < p.x() || (s.x() == p.x() && s.y() <= p.y())) << "trial " << trial << ": not the lowest start";
  }
  const std::size_t m = hull.size();
  if (m < 3) return;  // every point in one line: nothing turns
  for (std::size_t i = 0; i < m; ++i) {
    const Vec2 a = pts[hull[i]], b = pts[hull[(i + 1) % m]], c = pts[hull[(i + 2) % m]];
    ASSERT_GT((b - a).x() * (c - b).y() - (b - a).y() * (c - b).x(), 0) << "trial " << trial << " vertex " << i;
  }
  Polygon poly;
  for (int i : hull) poly.push_back(pts[i]);
  for (const Vec2& p : pts) ASSERT_TRUE(polygon_contains(poly, p, 1e-9)) << "trial " << trial;
}

// Up to 8 points (an object's box) the hull is taken by successors without a sort where the
// CPU has AVX2 (vector_clones.hpp); elsewhere, and from 9 points, by the monotone chain.
// Each hull is checked for what a hull is (above), so the test means the same on every
// CPU and in the plain x86-64 build (regions_plain_test). Where the CPU has AVX2 the two
// paths are also compared: copies of point 0 appended up to 9 points leave the hull as it
// is and take the chain. Points on a small grid repeat and line up often; Gaussian points
// are in general position.
TEST(ConvexHull, FewPointsGiveTheMonotoneChainsHull) {
  std::mt19937_64 rng(4);
  std::uniform_int_distribution<int> grid(0, 3);
  std::normal_distribution<double> g(0, 50);
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 3 + trial % 6;
    std::vector<Vec2> pts;
    for (int i = 0; i < n; ++i)
      pts.push_back(trial % 2 ? Vec2(grid(rng), grid(rng)) : Vec2(g(rng), 0.3 * g(rng)));
    const std::vector<int> few_ids = convex_hull_indices(pts);
    expect_is_the_hull(pts, few_ids, trial);
    std::vector<Vec2> padded = pts;
    padded.resize(9, pts[0]);
    const std::vector<int> chain_ids = convex_hull_indices(padded);
    expect_is_the_hull(padded, chain_ids, trial);
    ASSERT_EQ(few_ids.size(), chain_ids.size()) << "trial " << trial;
    for (std::size_t i = 0; i < few_ids.size(); ++i)
      ASSERT_EQ(pts[few_ids[i]], padded[chain_ids[i]]) << "trial " << trial << " vertex " << i;
  }
}

double distance_to_polygon_boundary(const Polygon& poly, const Vec2& q) {
  double best = 1e300;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2 a = poly[i], ab = poly[(i + 1) % poly.size()] - a;
    const double t = std::clamp((q - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (q - (a + t * ab)).norm());
  }
  return best;
}

// The outer region's guarantee: dense points of every ellipse all inside it, and every
// corner within the bound of their hull (which lies inside the true hull of the ellipses).
void expect_outer_guarantee(std::span<const ProjectedVertex> vertices, const Polygon& outer,
                            const RegionOptions& o, const std::string& what) {
  ASSERT_GE(outer.size(), 3u) << what;
  ASSERT_GT(polygon_area(outer), 0) << "counter-clockwise: " << what;
  const double scale = confidence_scale(o.confidence);
  std::vector<Vec2> dense;
  for (const ProjectedVertex& v : vertices) {
    const Eigen::SelfAdjointEigenSolver<Mat2> eig(v.covariance_px2);
    const Mat2 A = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
    for (int k = 0; k < 2000; ++k) {
      const double t = 2 * std::numbers::pi * k / 2000;
      dense.push_back(v.mean_px + scale * A * Vec2(std::cos(t), std::sin(t)));
      ASSERT_TRUE(polygon_contains(outer, dense.back(), 1e-7)) << what;
    }
  }
  const Polygon truth = convex_hull(dense);
  for (const Vec2& q : outer)
    EXPECT_LE(distance_to_polygon_boundary(truth, q), o.max_polygon_error_px + 0.01) << what;
}

// Random ellipses from tiny to huge, the shortcut where it applies and the search alone.
TEST(OuterRegion, ContainsEveryEllipseAndStaysWithinTheBound) {
  for (const bool by_arcs : {true, false}) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    RegionOptions o;
    o.outer_by_arcs = by_arcs;
    std::size_t corners = 0;
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<ProjectedVertex> vertices(2 + trial % 9);
      for (ProjectedVertex& v : vertices) {
        v.mean_px = Vec2(400 * u(rng), 300 * u(rng));
        const double size = std::pow(10.0, 3 * u(rng) - 1.5);  // 0.03 to 30: tiny to huge
        v.covariance_px2 = (u(rng) < 0.1 ? 0.0 : size * size) * random_covariance(rng) / 25;
      }
      const Polygon outer = expand_region(vertices, o);
      corners += outer.size();
      expect_outer_guarantee(vertices, outer, o, fmt::format("trial {}, by arcs {}", trial, by_arcs));
    }
    std::printf("outer region (by arcs %d): %.1f corners on average\n", by_arcs, double(corners) / 200);
  }
}

// Boxes as the benchmark frame has them: the shortcut applies to nearly all of them (its
// corners differ from the search's) and keeps the guarantee. About 4% of them need the
// mean hull mended first (an inner vertex's ellipse sticking out of an edge's tangent, a
// hull vertex's swallowed by its neighbours'): without that the shortcut applies to 95%.
TEST(OuterRegion, ShortcutAppliesToTypicalObjectsAndKeepsTheGuarantee) {
  const test::BenchFrame f = test::make_bench_frame(1000);
  RegionOptions search;
  search.outer_by_arcs = false;
  int shortcut = 0;
  for (std::size_t i = 0; i < f.poses.size(); ++i) {
    const std::vector<ProjectedVertex> vertices = project_vertices(f.camera, f.poses[i], f.vertices[i]);
    const Polygon by_arcs = expand_region(vertices, RegionOptions{});
    expect_outer_guarantee(vertices, by_arcs, RegionOptions{}, fmt::format("object {}", i));
    shortcut += by_arcs != expand_region(vertices, search);
  }
  std::printf("the shortcut applied to %d of %zu objects\n", shortcut, f.poses.size());
  EXPECT_GE(shortcut, 985);
}

// Zero covariance everywhere (sqrt(0) supports): the outer region is the hull of the
// centres, up to the tolerance (a corner may stand off an edge by at most
// max_polygon_error_px); one point or collinear points give themselves.
TEST(OuterRegion, ZeroCovarianceGivesTheHullOfTheCentres) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 400);
  const RegionOptions o;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<ProjectedVertex> vertices(3 + trial % 8);
    std::vector<Vec2> centres;
    for (ProjectedVertex& v : vertices) centres.push_back(v.mean_px = Vec2(u(rng), u(rng)));
    const Polygon outer = expand_region(vertices, o);
    ASSERT_TRUE(outer.size() >= 3 && outer.front().allFinite()) << "trial " << trial;
    const Polygon hull = convex_hull(centres);
    for (const Vec2& c : centres) EXPECT_TRUE(polygon_contains(outer, c, 1e-9)) << trial;
    for (const Vec2& q : outer)
      EXPECT_LE(distance_to_polygon_boundary(hull, q), o.max_polygon_error_px + 1e-9) << trial;
  }
  std::vector<ProjectedVertex> collinear(3);
  for (int i = 0; i < 3; ++i) collinear[i].mean_px = Vec2(10 + 5 * i, 20 + 5 * i);
  for (const Vec2& q : expand_region(collinear, o))
    EXPECT_LT(std::abs((q - Vec2(10, 20)).x() - (q - Vec2(10, 20)).y()), 1e-9) << "on the line";
  const Polygon point = expand_region(std::span(collinear).first(1), o);
  for (const Vec2& q : point) EXPECT_LT((q - Vec2(10, 20)).norm(), 1e-9);
}

TEST(Regions, WithoutErrorAllRegionsAreTheMeanHull) {
  const Camera cam = test::example_camera();
  const auto verts = box_vertices(0.2, 0.15, 0.1);
  ObjectRegionOptions o;
  o.projection.add_intrinsic_uncertainty = false;
  const ObjectRegions r = compute_object_regions(cam, box_pose(0, 0), verts, o);
  ASSERT_TRUE(r.valid);
  std::vector<Vec2> means;
  for (int i : r.hull) means.push_back(r.vertices[i].mean_px);
  const double hull_area = polygon_area(means);
  EXPECT_GT(hull_area, 100);
  EXPECT_NEAR(polygon_area(r.inner), hull_area, 1e-6 * hull_area);
  EXPECT_NEAR(polygon_area(r.outer), hull_area, 1e-6 * hull_area);
  EXPECT_NEAR(r.assessment, 0, 1e-9);
}

TEST(Regions, NestingInnerInHullInOuter) {
  const Camera cam = test::example_camera();
  const ObjectRegions r =
      compute_object_regions(cam, box_pose(0.003, 1 * kDeg), box_vertices(0.2, 0.15, 0.1));
  ASSERT_TRUE(r.valid);
  ASSERT_FALSE(r.inner.empty());
  Polygon hull;
  for (int i : r.hull) hull.push_back(r.vertices[i].mean_px);
  for (const Vec2& p : r.inner) EXPECT_TRUE(polygon_contains(hull, p, 1e-9));
  for (const Vec2& p : hull) EXPECT_TRUE(polygon_contains(r.outer, p, 1e-9));
  EXPECT_LT(polygon_area(r.inner), polygon_area(hull));
  EXPECT_GT(polygon_area(r.outer), polygon_area(hull));
}

// Each edge of the inner region lies on a line tangent to the confidence ellipses of two
// adjacent hull vertices (to 1e-5 px), both on its outer side.
void expect_inner_edges_are_interior_tangents(const ObjectRegions& r, const std::string& what) {
  const double scale = confidence_scale(0.95);
  ASSERT_TRUE(r.valid) << what;
  ASSERT_GE(r.inner.size(), 3u) << what;
  const auto min_over_ellipse = [&](const Vec2& n, int vertex) {
    const ProjectedVertex& v = r.vertices[vertex];
    return n.dot(v.mean_px) - scale * std::sqrt(n.dot(v.covariance_px2 * n));
  };
  for (std::size_t i = 0; i < r.inner.size(); ++i) {
    const Vec2 a = r.inner[i], b = r.inner[(i + 1) % r.inner.size()];
    const Vec2 n = Vec2(b.y() - a.y(), a.x() - b.x()).normalized();  // outward
    const double offset = n.dot(a);
    double best = 1e300;
    for (std::size_t h = 0; h < r.hull.size(); ++h) {
      const double gap_a = min_over_ellipse(n, r.hull[h]) - offset;
      const double gap_b = min_over_ellipse(n, r.hull[(h + 1) % r.hull.size()]) - offset;
      best = std::min(best, std::max(std::abs(gap_a), std::abs(gap_b)));
    }
    EXPECT_LT(best, 1e-5) << "edge " << i << " of " << what;
  }
}

TEST(Regions, InnerEdgesAreInteriorTangents) {
  const Camera cam = test::example_camera();
  for (double rotation_deg : {0.5, 1.0, 2.0})
    expect_inner_edges_are_interior_tangents(
        compute_object_regions(cam, box_pose(0.003, rotation_deg * kDeg), box_vertices(0.2, 0.15, 0.1)),
        std::to_string(rotation_deg) + " deg");
}

// The tangents are solved 8 hull edges at a time: a 13-gon needs a full block and a short one.
TEST(Regions, InnerEdgesAreInteriorTangentsBeyondOneBlock) {
  const Camera cam = test::example_camera();
  std::vector<Vec3> polygon;
  for (int k = 0; k < 13; ++k) {
    const double a = 2 * std::numbers::pi * k / 13;
    polygon.emplace_back(0.15 * std::cos(a), 0.1 * std::sin(a), 0.02 * (k % 2));
  }
  const ObjectRegions r = compute_object_regions(cam, box_pose(0.002, 0.5 * kDeg), polygon);
  ASSERT_EQ(r.hull.size(), 13u);
  expect_inner_edges_are_interior_tangents(r, "a 13-gon");
  // Every edge of the hull contributes: the inner region has 13 corners.
  EXPECT_EQ(r.inner.size(), 13u);
}

// The inner region is the intersection of the hull edges' interior tangent half-planes:
// its edges lie on such tangents (above), and it lies within every one of them, each found
// here by bisection on the angle, independently of the solver. Over the benchmark's 1,000
// objects, which include regions built from every edge's corners and regions where some
// tangent cuts off nothing (fewer corners than hull vertices), so both ways of building it.
TEST(Regions, InnerIsWithinEveryEdgesInteriorTangent) {
  const test::BenchFrame f = test::make_bench_frame(1000);
  const double scale = confidence_scale(0.95);
  int every_edge = 0, fewer = 0;
  for (std::size_t i = 0; i < f.poses.size(); ++i) {
    const ObjectRegions r = compute_object_regions(f.camera, f.poses[i], f.vertices[i]);
    if (!r.valid || r.inner.empty()) continue;
    (r.inner.size() == r.hull.size() ? every_edge : fewer) += 1;
    expect_inner_edges_are_interior_tangents(r, fmt::format("object {}", i));
    const std::size_t k = r.hull.size();
    for (std::size_t h = 0; h < k; ++h) {
      const ProjectedVertex& a = r.vertices[r.hull[h]];
      const ProjectedVertex& b = r.vertices[r.hull[(h + 1) % k]];
      const Vec2 e = b.mean_px - a.mean_px;
      const Vec2 n0 = Vec2(e.y(), -e.x()).normalized(), n1(-n0.y(), n0.x());
      const auto normal = [&](double theta) { return Vec2(std::cos(theta) * n0 + std::sin(theta) * n1); };
      const auto inner_support = [&](const ProjectedVertex& v, const Vec2& n) {
        return n.dot(v.mean_px) - scale * std::sqrt(n.dot(v.covariance_px2 * n));
      };
      const auto f_of = [&](double theta) {
        const Vec2 n = normal(theta);
        return inner_support(a, n) - inner_support(b, n);
      };
      double lo = -std::numbers::pi / 2 + 1e-9, hi = std::numbers::pi / 2 - 1e-9;
      if (!(f_of(lo) > 0 && f_of(hi) < 0)) continue;  // no such tangent: the solver's fallback
      for (int it = 0; it < 100; ++it) (f_of(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
      const Vec2 n = normal(lo);
      const double offset = std::min(inner_support(a, n), inner_support(b, n));
      for (const Vec2& q : r.inner) ASSERT_LE(n.dot(q), offset + 1e-6) << "object " << i << ", edge " << h;
    }
  }
  EXPECT_GT(every_edge, 100);
  EXPECT_GT(fewer, 10);
}

// An application keeps one ObjectRegions per object and recomputes it in place: nothing of
// an earlier object may survive into the next result.
TEST(Regions, RecomputedInPlaceEqualsAFreshResult) {
  const Camera cam = test::example_camera();
  std::vector<Vec3> big;
  for (int k = 0; k < 20; ++k)
    big.emplace_back(0.2 * std::cos(0.3 * k), 0.15 * std::sin(0.3 * k), 0.01 * k);
  UncertainPose behind = box_pose(0.005, 1 * kDeg);
  behind.T.translation().z() = -1;
  const auto box = box_vertices(0.2, 0.15, 0.1);
  const auto expect_same = [](const ObjectRegions& a, const ObjectRegions& b, const char* what) {
    EXPECT_EQ(a.valid, b.valid) << what;
    EXPECT_EQ(a.hull, b.hull) << what;
    EXPECT_EQ(a.outer, b.outer) << what;
    EXPECT_EQ(a.inner, b.inner) << what;
    EXPECT_EQ(a.flags.any(), b.flags.any()) << what;
    EXPECT_EQ(a.flags.behind_camera, b.flags.behind_camera) << what;
    EXPECT_TRUE(a.assessment == b.assessment || (std::isinf(a.assessment) && std::isinf(b.assessment))) << what;
    ASSERT_EQ(a.vertices.size(), b.vertices.size()) << what;
    for (std::size_t i = 0; i < a.vertices.size(); ++i) {
      EXPECT_EQ(a.vertices[i].mean_px, b.vertices[i].mean_px) << what;
      EXPECT_EQ(a.vertices[i].covariance_px2, b.vertices[i].covariance_px2) << what;
    }
  };
  ObjectRegions reused;
  const ObjectRegionOptions o;
  compute_object_regions(cam, box_pose(0.02, 4 * kDeg), big, o, reused);  // large, flagged
  compute_object_regions(cam, box_pose(0.003, 1 * kDeg), box, o, reused);
  expect_same(reused, compute_object_regions(cam, box_pose(0.003, 1 * kDeg), box, o), "box after a bigger object");
  compute_object_regions(cam, behind, box, o, reused);
  expect_same(reused, compute_object_regions(cam, behind, box, o), "invalid after valid");
  compute_object_regions(cam, box_pose(0.003, 1 * kDeg), box, o, reused);
  expect_same(reused, compute_object_regions(cam, box_pose(0.003, 1 * kDeg), box, o), "valid after invalid");
}

// Sample true poses; each projected vertex must fall in the outer region (>= 95%), and the
// inner region must lie inside the true object's projected hull (>= 95% of samples).
void check_honesty(double translation_sigma_m, double rotation_sigma_rad) {
  const Camera cam = test::example_camera();
  const auto verts = box_vertices(0.2, 0.15, 0.1);
  const UncertainPose pose = box_pose(translation_sigma_m, rotation_sigma_rad);
  ObjectRegionOptions o;
  o.projection.add_intrinsic_uncertainty = false;
  const ObjectRegions r = compute_object_regions(cam, pose, verts, o);
  ASSERT_TRUE(r.valid);
  ASSERT_FALSE(r.inner.empty());

  std::mt19937_64 rng(99);
  std::normal_distribution<double> normal;
  const Mat6 L = Eigen::LLT<Mat6>(pose.covariance).matrixL();
  const int samples = 20000;
  int vertices_in_outer = 0, inner_inside_truth = 0;
  for (int s = 0; s < samples; ++s) {
    Vec6 z;
    for (int k = 0; k < 6; ++k) z[k] = normal(rng);
    const Pose T = pose.T * se3_exp(L * z);
    std::vector<Vec2> px;
    for (const Vec3& v : verts) {
      px.push_back(cam.project(T * v));
      vertices_in_outer += polygon_contains(r.outer, px.back(), 0);
    }
    const Polygon truth = convex_hull(px);
    bool inside = true;
    for (const Vec2& p : r.inner) inside = inside && polygon_contains(truth, p, 0);
    inner_inside_truth += inside;
  }
  const double outer_rate = double(vertices_in_outer) / (samples * verts.size());
  const double inner_rate = double(inner_inside_truth) / samples;
  std::printf("sigma %.0f mm, %.0f deg: vertices in outer %.4f, inner inside truth %.4f "
              "(areas: inner %.0f, outer %.0f px^2)\n",
              translation_sigma_m * 1e3, rotation_sigma_rad / kDeg, outer_rate, inner_rate,
              polygon_area(r.inner), polygon_area(r.outer));
  EXPECT_GE(outer_rate, 0.95);
  EXPECT_GE(inner_rate, 0.95);
}

TEST(Regions, HonestOnMonteCarloSmallError) { check_honesty(0.005, 2 * kDeg); }
TEST(Regions, HonestOnMonteCarloRotationDominated) { check_honesty(0.002, 5 * kDeg); }

TEST(Regions, InnerEmptyWhenErrorSwampsTheObject) {
  const Camera cam = test::example_camera();
  const ObjectRegions r =
      compute_object_regions(cam, box_pose(0.1, 1 * kDeg), box_vertices(0.2, 0.15, 0.1));
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.inner.empty());
  EXPECT_GT(polygon_area(r.outer), 0);
}

TEST(Regions, DegenerateHullHasNoInner) {
  const Camera cam = test::example_camera();
  const std::vector<Vec3> segment = {Vec3(-0.1, 0, 0), Vec3(0.1, 0, 0)};
  const ObjectRegions r = compute_object_regions(cam, box_pose(0.002, 0.5 * kDeg), segment);
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.inner.empty());
  EXPECT_GT(polygon_area(r.outer), 0);  // two ellipses still span an area
}

TEST(Regions, InvalidWhenBehindCamera) {
  const Camera cam = test::example_camera();
  UncertainPose pose = box_pose(0.005, 1 * kDeg);
  pose.T.translation().z() = -1;
  const ObjectRegions r = compute_object_regions(cam, pose, box_vertices(0.2, 0.15, 0.1));
  EXPECT_FALSE(r.valid);
  EXPECT_TRUE(r.flags.behind_camera);
  EXPECT_TRUE(r.outer.empty());
  EXPECT_TRUE(r.inner.empty());
  EXPECT_TRUE(std::isinf(r.assessment));
}

// The whole-object scale's angles (angle_bound.hpp): never below the true angle, at most
// 2e-5 rad above it, over every direction and at any common scale of the two parts (its
// callers pass vectors that are not normalised); the ends, the axes and no vector exactly;
// a NaN stays one.
TEST(AngleBound, IsAtMostTwoE5AboveTheTrueAngle) {
  const double pi = std::numbers::pi;
  double worst_below = 0, worst_above = 0;
  for (int i = 0; i <= 200000; ++i) {
    const double angle = pi * i / 200000;
    for (const double scale : {1e-120, 1e-6, 1.0, 3e4, 1e120}) {
      const double y = std::max(scale * std::sin(angle), 0.0), x = scale * std::cos(angle);
      const double truth = std::atan2(y, x), bound = angle_at_most(y, x);
      worst_below = std::max(worst_below, truth - bound);
      worst_above = std::max(worst_above, bound - truth);
    }
  }
  std::printf("angle bound: at most %.2e above the truth and %.2e below it\n", worst_above, worst_below);
  EXPECT_LE(worst_below, 0.0);
  EXPECT_LE(worst_above, 2e-5);
  EXPECT_DOUBLE_EQ(angle_at_most(0, 1), 1e-5);
  EXPECT_DOUBLE_EQ(angle_at_most(0, 0), 1e-5);  // no vector: no angle but the margin
  EXPECT_DOUBLE_EQ(angle_at_most(0, -1), pi);
  EXPECT_NEAR(angle_at_most(1, 0), pi / 2, 2e-5);
  EXPECT_GE(angle_at_most(1, 0), pi / 2);
  EXPECT_TRUE(std::isnan(angle_at_most(std::numeric_limits<double>::quiet_NaN(), 1)));
}

// The whole-object scale's curve length, against the same length summed edge by edge
// here: for each hull edge the jump between its two vertices' whitened directions (the
// angle between J_a^T n and J_b^T n in the pose covariance's metric) and its end vertex's
// arc from this edge's normal to the next one's (in that vertex's pixel covariance), with
// exact angles. The library's angles are upper bounds within 2e-5 rad, so its length lies
// in [L, L + 4e-5 k]. Hulls of 3 to 22 vertices, so that edges fall on both sides of the
// library's block boundaries (7 edges a block); an undistorted camera, where its pinhole
// Jacobians are exact.
TEST(WholeObjectScale, IsTheCurveLengthSummedEdgeByEdge) {
  Camera cam = test::example_camera();
  cam.k1 = cam.k2 = cam.k3 = cam.p1 = cam.p2 = 0;
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(-1, 1);
  Mat6 A;
  for (int i = 0; i < 36; ++i) A(i / 6, i % 6) = u(rng);
  const Vec6 scale = (Vec6() << 0.004, 0.004, 0.008, 0.03, 0.03, 0.03).finished();
  const UncertainPose pose{pose_from(Vec3(0.05, -0.03, 1.2), Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Vec3(1, 0.3, 0.2).normalized()))),
                           scale.asDiagonal() * (A * A.transpose() + 0.1 * Mat6::Identity()) * scale.asDiagonal(), false};
  ProjectionOptions o;
  o.method = ProjectionMethod::linear;
  o.add_intrinsic_uncertainty = false;
  const double chi2_2 = std::pow(confidence_scale(0.95), 2);
  for (int n : {3, 5, 7, 8, 9, 14, 15, 16, 22}) {
    std::vector<Vec3> points;
    for (int i = 0; i < n; ++i) {
      const double a = 2 * std::numbers::pi * i / n;
      points.emplace_back(0.1 * std::cos(a), 0.07 * std::sin(a), 0.01 * std::sin(3 * a));
    }
    const std::vector<ProjectedVertex> projected = project_vertices(cam, pose, points, o);
    std::vector<Vec2> means;
    for (const ProjectedVertex& v : projected) means.push_back(v.mean_px);
    std::vector<int> hull;
    convex_hull_indices(means, hull);
    const std::size_t k = hull.size();
    ASSERT_EQ(k, static_cast<std::size_t>(n)) << "every point of the ring is on the hull";
    const auto normal = [&](std::size_t e) {  // outward normal of the counter-clockwise edge e
      const Vec2 d = means[hull[(e + 1) % k]] - means[hull[e]];
      return Vec2(d.y(), -d.x()).normalized();
    };
    double length = 0;
    for (std::size_t e = 0; e < k; ++e) {
      const std::size_t f = (e + 1) % k;
      const Vec2 n_e = normal(e), n_f = normal(f);
      const Vec6 a = pixel_jacobian_wrt_perturbation(cam, pose.T, points[hull[e]]).transpose() * n_e;
      const Vec6 b = pixel_jacobian_wrt_perturbation(cam, pose.T, points[hull[f]]).transpose() * n_e;
      const double aa = a.dot(pose.covariance * a), ab = a.dot(pose.covariance * b), bb = b.dot(pose.covariance * b);
      const Mat2& S = projected[hull[f]].covariance_px2;
      const double turn = std::abs(n_e.x() * n_f.y() - n_e.y() * n_f.x());
      length += std::atan2(std::sqrt(std::max(aa * bb - ab * ab, 0.0)), ab) +
                std::atan2(std::sqrt(S.determinant()) * turn, n_e.dot(S * n_f));
    }
    const double s2 = whole_object_scale2(cam, pose, points, projected, hull, 0.95);
    ASSERT_LT(s2, chi2_6_quantile(0.95)) << n << " vertices: the cap hides the length";
    const double library_length = 2 * std::numbers::pi * std::exp((s2 - chi2_2) / 2);
    std::printf("%2d vertices: length %.4f, the library's %.4f\n", n, length, library_length);
    EXPECT_GE(library_length, length * (1 - 1e-9)) << n << " vertices";
    EXPECT_LE(library_length, length + 4e-5 * k) << n << " vertices";
  }
}

// Numbers no tracker reports, as a damaged message or an application's bug could hand
// them over: the object is invalid and says why, never a region of NaNs (fuzz_regions
// found regions of NaNs, and a set of supports that overflowed split for a second).
TEST(Regions, InvalidAndFlaggedWhenNumbersAreNotFinite) {
  Camera cam = test::example_camera();
  const std::vector<Vec3> box = box_vertices(0.2, 0.15, 0.1);
  // `methods`: the projections that must flag it (the others' may find another reason).
  const auto expect_not_finite = [&](const UncertainPose& pose, const std::vector<Vec3>& vertices,
                                     const std::string& what,
                                     std::vector<ProjectionMethod> methods = {ProjectionMethod::unscented,
                                                                              ProjectionMethod::linear}) {
    for (const ProjectionMethod method : {ProjectionMethod::unscented, ProjectionMethod::linear}) {
      ObjectRegionOptions o;
      o.projection.method = method;
      const ObjectRegions r = compute_object_regions(cam, pose, vertices, o);
      EXPECT_FALSE(r.valid) << what;
      if (std::ranges::find(methods, method) != methods.end()) {
        EXPECT_TRUE(r.flags.not_finite) << what;
      }
      EXPECT_TRUE(r.outer.empty() && r.inner.empty()) << what;
      EXPECT_TRUE(std::isinf(r.assessment)) << what;
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  UncertainPose pose = box_pose(0.005, 1 * kDeg);
  pose.T.translation().x() = nan;
  expect_not_finite(pose, box, "NaN position");
  pose = box_pose(0.005, 1 * kDeg);
  pose.covariance(3, 3) = std::numeric_limits<double>::infinity();
  expect_not_finite(pose, box, "infinite covariance");
  std::vector<Vec3> bad = box;
  bad[3].y() = nan;
  expect_not_finite(box_pose(0.005, 1 * kDeg), bad, "NaN vertex");
  // The vertex flag alone, and the good vertices of the same object keep theirs.
  const ObjectRegions r = compute_object_regions(cam, box_pose(0.005, 1 * kDeg), bad);
  for (std::size_t i = 0; i < bad.size(); ++i) EXPECT_EQ(r.vertices[i].flags.not_finite, i == 3) << i;
  // Finite, but the pixels' covariance overflows (variances near 1e310 px^2), or finite
  // pixels' confidence ellipses do (about 1e307 px^2 times the scale): first order. (The
  // unscented transform's sigma points that far out lie behind the camera, or with a lens
  // past its distortion fold: also invalid, for that reason.)
  cam.k1 = cam.k2 = cam.k3 = cam.p1 = cam.p2 = 0;
  for (const double variance : {1e305, 4e302}) {
    pose = box_pose(0.005, 1 * kDeg);
    pose.covariance(0, 0) = variance;
    expect_not_finite(pose, box, fmt::format("x variance {}", variance), {ProjectionMethod::linear});
  }
}

// The first-order projection of an indefinite pose covariance is repaired and flagged, as
// the unscented transform's is, rather than handed on with a negative variance.
TEST(Regions, LinearProjectionRepairsAnIndefiniteCovariance) {
  const Camera cam = test::example_camera();
  UncertainPose pose = box_pose(0.005, 1 * kDeg);
  pose.covariance(0, 0) = -1e-3;  // x known to a negative variance
  ObjectRegionOptions o;
  o.projection.method = ProjectionMethod::linear;
  const ObjectRegions r = compute_object_regions(cam, pose, box_vertices(0.2, 0.15, 0.1), o);
  EXPECT_TRUE(r.flags.covariance_repaired);
  for (const ProjectedVertex& v : r.vertices) {
    EXPECT_GE(v.covariance_px2.trace(), 0);
    EXPECT_GE(v.covariance_px2.determinant(), -1e-9 * v.covariance_px2.squaredNorm());
  }
  ASSERT_TRUE(r.valid);
  EXPECT_GE(r.assessment, 0);
}

TEST(Assessment, MetricsAndAggregators) {
  ProjectedVertex a, b;
  a.mean_px = {0, 0};
  a.covariance_px2 << 4, 0, 0, 1;  // semi-axes 2 and 1 px at 1 sigma
  b.mean_px = {100, 0};
  b.covariance_px2 << 9, 0, 0, 9;  // circle of radius 3 px
  const std::vector<ProjectedVertex> vs = {a, b};
  const double s = confidence_scale(0.95);
  EXPECT_NEAR(s, 2.447746830680816, 1e-12);
  EXPECT_NEAR(largest_semi_axis_px(0.95)(a), 2 * s, 1e-12);
  EXPECT_NEAR(ellipse_area_px2(0.95)(b), std::numbers::pi * 9 * s * s, 1e-9);
  EXPECT_NEAR(assess(default_assessment(), vs), 3 * s, 1e-12);
  EXPECT_NEAR(assess({largest_semi_axis_px(0.95), mean_value()}, vs), 2.5 * s, 1e-12);
  EXPECT_NEAR(assess({largest_semi_axis_px(0.95), nearest_vertex_to(Vec2(10, 5))}, vs), 2 * s, 1e-12);
  // Pluggable: any callable.
  const Assessment custom{[](const ProjectedVertex& v) { return v.covariance_px2.trace(); },
                          [](auto, std::span<const double> x) { return x[0] + x[1]; }};
  EXPECT_DOUBLE_EQ(assess(custom, vs), 23.0);
  std::vector<ProjectedVertex> bad = vs;
  bad[1].flags.sigma_point_behind_camera = true;
  EXPECT_TRUE(std::isinf(assess(default_assessment(), bad)));
  // A metric may assess other vertices itself: the inner call must not disturb the outer.
  const Assessment nested{[&](const ProjectedVertex& v) { return v.covariance_px2.trace() + assess(custom, vs); },
                          [](auto, std::span<const double> x) { return x[0] + x[1]; }};
  EXPECT_DOUBLE_EQ(assess(nested, vs), 23.0 + 2 * 23.0);
}

TEST(Assessment, SemiMajorAxisAloneEqualsTheFullAxes) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 100; ++trial) {
    const Mat2 C = random_covariance(rng);
    EXPECT_NEAR(ellipse_semi_major_px(C), ellipse_axes(C).major_px, 1e-12 * ellipse_axes(C).major_px);
  }
}
