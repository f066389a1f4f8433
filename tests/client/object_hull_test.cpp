// The 3-D hull of an object's vertices: which points it keeps, flat and degenerate sets,
// bad input, and the reason it exists: projecting only the hull loses no screen hull point.
#include <algorithm>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "example_camera.hpp"

#include "covtrack/client/object_hull.hpp"
#include "covtrack/client/regions.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Vec3(n(rng), n(rng), n(rng)).normalized();
}

}  // namespace

TEST(ObjectHull, KeepsPointsOnASphereAndDropsThoseInside) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> radius(0.0, 0.5);
  std::vector<Vec3> points;
  for (int i = 0; i < 200; ++i) {
    points.push_back(random_unit(rng));                 // on the hull: even index
    points.push_back(radius(rng) * random_unit(rng));   // strictly inside: odd index
  }
  const auto ids = convex_hull_indices_3d(points);
  ASSERT_TRUE(ids) << ids.error().message;
  std::vector<int> expected;
  for (int i = 0; i < 400; i += 2) expected.push_back(i);
  EXPECT_EQ(*ids, expected);
}

TEST(ObjectHull, BoxKeepsItsEightCorners) {
  std::vector<Vec3> points;
  for (int i = 0; i < 8; ++i)
    points.emplace_back(i & 1 ? 0.3 : -0.3, i & 2 ? 0.1 : -0.1, i & 4 ? 0.02 : -0.02);
  points.emplace_back(0, 0, 0);          // centre
  points.emplace_back(0.3, 0.0, 0.0);    // middle of a face
  points.emplace_back(0.0, 0.1, 0.02);   // middle of an edge
  const auto ids = convex_hull_indices_3d(points);
  ASSERT_TRUE(ids) << ids.error().message;
  EXPECT_EQ(*ids, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
}

TEST(ObjectHull, FlatQuadIsHandledInItsPlane) {
  // A tilted square with its centre and an edge midpoint: qhull alone rejects flat input.
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  std::vector<Vec3> points = {R * Vec3(-1, -1, 0), R * Vec3(1, -1, 0), R * Vec3(0, 0, 0),
                              R * Vec3(1, 1, 0),   R * Vec3(0, 1, 0),  R * Vec3(-1, 1, 0)};
  const auto ids = convex_hull_indices_3d(points);
  ASSERT_TRUE(ids) << ids.error().message;
  EXPECT_EQ(*ids, (std::vector<int>{0, 1, 3, 5}));
}

TEST(ObjectHull, LineKeepsItsEndsAndAPointItself) {
  const std::vector<Vec3> line = {Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(0.2, 0.2, 0.2)};
  const auto ends = convex_hull_indices_3d(line);
  ASSERT_TRUE(ends);
  EXPECT_EQ(*ends, (std::vector<int>{1, 2}));
  const std::vector<Vec3> same = {Vec3(1, 2, 3), Vec3(1, 2, 3)};
  const auto one = convex_hull_indices_3d(same);
  ASSERT_TRUE(one);
  EXPECT_EQ(one->size(), 1u);
}

TEST(ObjectHull, RejectsEmptyAndNonFiniteInput) {
  EXPECT_FALSE(convex_hull_indices_3d({}));
  const std::vector<Vec3> bad = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, std::nan(""), 0), Vec3(0, 0, 1)};
  const auto r = convex_hull_indices_3d(bad);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("vertex 2"), std::string::npos) << r.error().message;
}

TEST(ObjectHull, ProjectingTheHullLosesNoScreenHullPointThroughAPinhole) {
  Camera camera = test::example_camera();
  camera.k1 = camera.k2 = camera.p1 = camera.p2 = camera.k3 = 0;  // see object_hull.hpp
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 0.15);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Vec3> object;
    for (int i = 0; i < 60; ++i) object.emplace_back(n(rng), n(rng), n(rng));
    const auto ids = convex_hull_indices_3d(object);
    ASSERT_TRUE(ids);
    const Pose T_camera_object =
        pose_from(Vec3(n(rng), n(rng), 2.0), Eigen::Quaterniond(Eigen::AngleAxisd(3 * n(rng), random_unit(rng))));
    std::vector<Vec2> all;
    for (const Vec3& p : object) all.push_back(camera.project(T_camera_object * p));
    for (int i : convex_hull_indices(all))
      EXPECT_TRUE(std::binary_search(ids->begin(), ids->end(), i))
          << "screen hull point " << i << " is not a 3-D hull vertex (trial " << trial << ")";
  }
}

// The hull's triangles close a surface around every point, facing out: each edge is used
// once in each direction, every point is behind every triangle's plane, and the enclosed
// volume (divergence theorem) is the box's.
TEST(ObjectHull, TrianglesCloseTheHullFacingOut) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g;
  std::vector<Vec3> points;
  for (int i = 0; i < 300; ++i) points.push_back(Vec3(g(rng), g(rng), 0.5 * g(rng)));
  auto triangles = convex_hull_triangles_3d(points);
  ASSERT_TRUE(triangles) << triangles.error().message;
  ASSERT_GE(triangles->size(), 4u);
  std::map<std::pair<int, int>, int> edges;
  for (const Triangle& t : *triangles) {
    const Vec3 n = (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]);
    for (const Vec3& p : points) EXPECT_LE(n.dot(p - points[t[0]]), 1e-9 * n.norm());
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
  }
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(edges.count({edge.second, edge.first}), 1u) << edge.first << "-" << edge.second;
  }

  std::vector<Vec3> box;
  for (int i = 0; i < 8; ++i) box.emplace_back(i & 1 ? 0.04 : -0.04, i & 2 ? 0.03 : -0.03, i & 4 ? 0.02 : -0.02);
  box.push_back(Vec3(0.01, 0, 0));  // inside: left out
  auto box_triangles = convex_hull_triangles_3d(box);
  ASSERT_TRUE(box_triangles);
  EXPECT_EQ(box_triangles->size(), 12u);
  double volume = 0;
  for (const Triangle& t : *box_triangles) volume += box[t[0]].dot(box[t[1]].cross(box[t[2]])) / 6;
  EXPECT_NEAR(volume, 0.08 * 0.06 * 0.04, 1e-12);

  // A flat quad: a fan of two; a line: none.
  const std::vector<Vec3> quad = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  EXPECT_EQ(convex_hull_triangles_3d(quad)->size(), 2u);
  const std::vector<Vec3> line = {Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2)};
  EXPECT_TRUE(convex_hull_triangles_3d(line)->empty());
  EXPECT_FALSE(convex_hull_triangles_3d({}));
}
