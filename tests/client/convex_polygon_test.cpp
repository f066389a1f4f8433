// Linear-time convex intersection against hand-computed areas and against clipping.
#include <cmath>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "covtrack/client/convex_polygon.hpp"
#include "support/convex_clipping.hpp"
#include "widget_polygons.hpp"

using namespace covtrack::client;
using covtrack::client::widget_testing::square;

namespace {

std::string text(const Polygon& p) {
  std::ostringstream out;
  out.precision(17);
  for (const Vec2& v : p) out << "(" << v.x() << ", " << v.y() << ") ";
  return out.str();
}

// Every vertex of `a` lies in `b` (within tol) and the other way round.
void expect_same_region(const Polygon& a, const Polygon& b, double tol, const char* what) {
  for (const Vec2& v : a) EXPECT_TRUE(polygon_contains(b, v, tol)) << what << " " << v.transpose();
  for (const Vec2& v : b) EXPECT_TRUE(polygon_contains(a, v, tol)) << what << " " << v.transpose();
}
}  // namespace

TEST(ConvexIntersection, HandMadeAreas) {
  const Polygon unit = square(0, 0, 1, 1);
  EXPECT_NEAR(polygon_area(intersect_convex(unit, square(0.5, 0.5, 1.5, 1.5))), 0.25, 1e-12);
  EXPECT_NEAR(polygon_area(intersect_convex(unit, unit)), 1.0, 1e-12);  // all edges shared
  EXPECT_NEAR(polygon_area(intersect_convex(square(-5, -5, 5, 5), unit)), 1.0, 1e-12);
  EXPECT_TRUE(intersect_convex(unit, square(2, 0, 3, 1)).empty());
  EXPECT_TRUE(intersect_convex(unit, square(1, 0, 2, 1)).empty()) << "touching edges only";
  // Square [-1,1]^2 and the diamond |x| + |y| <= 1.5: four corners of 0.125 cut away.
  const Polygon diamond = {Vec2(1.5, 0), Vec2(0, 1.5), Vec2(-1.5, 0), Vec2(0, -1.5)};
  const Polygon octagon = intersect_convex(square(-1, -1, 1, 1), diamond);
  EXPECT_NEAR(polygon_area(octagon), 3.5, 1e-12);
  EXPECT_EQ(octagon.size(), 8u);
  // A triangle over half of a square.
  const Polygon triangle = {Vec2(0, 0), Vec2(10, 0), Vec2(0, 10)};
  EXPECT_NEAR(polygon_area(intersect_convex(square(0, 0, 10, 10), triangle)), 50, 1e-9);
  // Degenerate inputs give nothing rather than garbage.
  EXPECT_TRUE(intersect_convex(unit, {Vec2(0, 0), Vec2(1, 1)}).empty());
  EXPECT_TRUE(intersect_convex({}, unit).empty());
}

TEST(ConvexIntersection, EqualsClippingOnRandomConvexPolygons) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> offset(-12, 12);
  int overlapping = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const bool grid = trial % 2 == 1;  // integer grid: shared vertices, collinear edges
    const Polygon a = widget_testing::random_convex(rng, Vec2(0, 0), 10, 25, grid);
    Vec2 shift(offset(rng), offset(rng));
    if (grid) shift = shift.array().round().matrix();
    const Polygon b = widget_testing::random_convex(rng, shift, 1 + trial % 10, 25, grid);
    const Polygon fast = intersect_convex(a, b);
    const Polygon slow = reference::intersect_convex_by_clipping(a, b);
    const double area = polygon_area(slow);
    ASSERT_NEAR(polygon_area(fast), area, 1e-9 * (1 + area))
        << "trial " << trial << "\na: " << text(a) << "\nb: " << text(b);
    EXPECT_NEAR(polygon_area(intersect_convex(b, a)), area, 1e-9 * (1 + area)) << "trial " << trial;
    if (area > 1e-9) {
      ++overlapping;
      EXPECT_GT(polygon_area(fast), 0) << "counter-clockwise, trial " << trial;
      expect_same_region(fast, slow, 1e-7, "random");
    }
  }
  EXPECT_GT(overlapping, 1000) << "most pairs must overlap for the comparison to mean much";
}

TEST(ConvexIntersection, PolygonWithItselfAndWithLargePixelCoordinates) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const Polygon a = widget_testing::random_convex(rng, Vec2(1e4, -3e3), 50);
    EXPECT_NEAR(polygon_area(intersect_convex(a, a)), polygon_area(a), 1e-9 * polygon_area(a));
  }
}

TEST(PolygonCentroid, OfASquareAndATriangle) {
  EXPECT_TRUE(polygon_centroid(square(2, 4, 6, 10)).isApprox(Vec2(4, 7)));
  const Polygon triangle = {Vec2(0, 0), Vec2(3, 0), Vec2(0, 3)};
  EXPECT_TRUE(polygon_centroid(triangle).isApprox(Vec2(1, 1)));
  EXPECT_NEAR(polygon_radius(square(-1, -1, 1, 1), Vec2(0, 0)), std::sqrt(2.0), 1e-12);
}

// The allocating clip sizes its output for any polygon: a comb whose teeth cross the line
// six times gives 12 points, more than the size + 1 a convex polygon can (this wrote past
// the end of its output once).
TEST(ClipHalfPlane, ANonConvexPolygonKeepsEveryCrossing) {
  const Polygon comb = {Vec2(0, 0), Vec2(1, 1), Vec2(2, 0), Vec2(3, 1), Vec2(4, 0),
                        Vec2(5, 1), Vec2(6, 0), Vec2(6, -1), Vec2(0, -1)};
  const Polygon below = clip_half_plane(comb, Vec2(0, 1), 0.5);
  const Polygon expected = {Vec2(0, 0),   Vec2(0.5, 0.5), Vec2(1.5, 0.5), Vec2(2, 0),  Vec2(2.5, 0.5),
                            Vec2(3.5, 0.5), Vec2(4, 0),   Vec2(4.5, 0.5), Vec2(5.5, 0.5), Vec2(6, 0),
                            Vec2(6, -1),  Vec2(0, -1)};
  ASSERT_EQ(below.size(), expected.size()) << text(below);
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_TRUE(below[i].isApprox(expected[i], 1e-12)) << text(below);
}
