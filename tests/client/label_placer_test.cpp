// Label placer and space manager: inside inner / outside outer, no overlaps, on screen,
// policies, the corner list; on hand-made and random polygons.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "covtrack/client/convex_polygon.hpp"
#include "support/convex_clipping.hpp"
#include "covtrack/client/label_placer.hpp"
#include "covtrack/client/space_manager.hpp"
#include "widget_polygons.hpp"

using namespace covtrack::client;
using covtrack::client::widget_testing::square;

namespace {

const Box kScreen{Vec2(0, 0), Vec2(640, 480)};


// The region shrunk towards its centroid: an inner region inside the outer one.
Polygon shrunk(const Polygon& p, double factor) {
  const Vec2 c = polygon_centroid(p);
  Polygon out;
  for (const Vec2& v : p) out.push_back(c + factor * (v - c));
  return out;
}

// Independent of the placer's own tests: area the box cuts out of the polygon.
double shared_area(const Box& box, const Polygon& convex) {
  return polygon_area(reference::intersect_convex_by_clipping(convex, box_polygon(box)));
}

bool corners_inside(const Box& box, const Polygon& convex) {
  for (const Vec2& c : box_polygon(box))
    if (!polygon_contains(convex, c, 1e-6)) return false;
  return true;
}

void expect_no_overlaps(const std::vector<PlacedLabel>& labels) {
  for (std::size_t i = 0; i < labels.size(); ++i)
    for (std::size_t j = i + 1; j < labels.size(); ++j)
      EXPECT_FALSE(boxes_overlap(labels[i].box, labels[j].box)) << i << " and " << j;
}

}  // namespace

TEST(LabelPlacer, InsideTheInnerRegionWhenItFits) {
  const Polygon outer = square(100, 100, 300, 250), inner = square(130, 130, 270, 220);
  const LabelRequest request{inner, outer, Vec2(80, 20)};
  const auto labels = place_labels(std::span(&request, 1), {.screen = kScreen});
  ASSERT_EQ(labels.size(), 1u);
  EXPECT_EQ(labels[0].placement, LabelPlacement::inside_inner);
  EXPECT_TRUE(labels[0].anchored);
  EXPECT_FALSE(labels[0].leader);
  EXPECT_TRUE(corners_inside(labels[0].box, inner));
  EXPECT_NEAR(labels[0].box.width(), 80, 1e-9);
  EXPECT_TRUE(labels[0].box.center().isApprox(Vec2(200, 175))) << "centred in the inner region";
}

TEST(LabelPlacer, InATriangleOnlyWhereTheWholeBoxFits) {
  // A right triangle whose centroid region is too narrow for a wide box near the tip.
  const Polygon inner = {Vec2(100, 100), Vec2(400, 100), Vec2(100, 400)};
  const LabelRequest request{inner, shrunk(inner, 1.2), Vec2(120, 30)};
  const auto labels = place_labels(std::span(&request, 1), {.screen = kScreen});
  EXPECT_EQ(labels[0].placement, LabelPlacement::inside_inner);
  EXPECT_TRUE(corners_inside(labels[0].box, inner));
  // Far too big for it: outside.
  // Width + height above the legs (300): no position fits; outside, on a larger screen.
  const LabelRequest big{inner, shrunk(inner, 1.2), Vec2(200, 150)};
  const Box large_screen{Vec2(0, 0), Vec2(1280, 960)};
  EXPECT_EQ(place_labels(std::span(&big, 1), {.screen = large_screen})[0].placement,
            LabelPlacement::outside_outer);
  const LabelRequest fits{inner, shrunk(inner, 1.2), Vec2(160, 130)};
  const auto placed = place_labels(std::span(&fits, 1), {.screen = kScreen});
  EXPECT_EQ(placed[0].placement, LabelPlacement::inside_inner);
  EXPECT_TRUE(corners_inside(placed[0].box, inner));
}

TEST(LabelPlacer, OutsideTheOuterRegionWithALeaderWhenTheInnerIsTooSmall) {
  const Polygon outer = square(200, 200, 300, 260), inner = square(240, 225, 260, 235);
  const LabelRequest request{inner, outer, Vec2(80, 20)};
  const auto labels = place_labels(std::span(&request, 1), {.screen = kScreen, .gap_px = 4});
  ASSERT_EQ(labels[0].placement, LabelPlacement::outside_outer);
  EXPECT_TRUE(labels[0].anchored);
  EXPECT_EQ(shared_area(labels[0].box, outer), 0);
  EXPECT_GE(labels[0].box.min.x(), 304 - 1e-9) << "right of the object (fixed order)";
  ASSERT_TRUE(labels[0].leader);
  EXPECT_TRUE((*labels[0].leader)[1].isApprox(Vec2(250, 230))) << "leader ends at the object";
  EXPECT_TRUE(box_inside(Box{(*labels[0].leader)[0], (*labels[0].leader)[0]}, labels[0].box))
      << "leader starts on the label";
}

TEST(LabelPlacer, FixedOrderTriesRightTopBottomLeft) {
  const Vec2 size(100, 30);
  const auto side_of = [&](const Polygon& outer) {
    const LabelRequest request{{}, outer, size};
    const Box b = place_labels(std::span(&request, 1), {.screen = kScreen})[0].box;
    const Box o = bounding_box(outer);
    if (b.min.x() >= o.max.x()) return 'R';
    if (b.max.y() <= o.min.y()) return 'T';
    if (b.min.y() >= o.max.y()) return 'B';
    if (b.max.x() <= o.min.x()) return 'L';
    return '?';
  };
  EXPECT_EQ(side_of(square(200, 200, 300, 260)), 'R');
  EXPECT_EQ(side_of(square(560, 200, 630, 260)), 'T');  // no room on the right
  EXPECT_EQ(side_of(square(560, 5, 630, 60)), 'B');     // nor on top
  EXPECT_EQ(side_of(square(560, 10, 630, 470)), 'L');   // nor above or below (tall)
}

TEST(LabelPlacer, MostFreeSpacePicksTheWidestSide) {
  const LabelPlacerOptions options{.screen = kScreen, .policy = most_free_space_policy()};
  const auto placed = [&](const Polygon& outer) {
    const LabelRequest request{{}, outer, Vec2(60, 20)};
    return place_labels(std::span(&request, 1), options)[0].box;
  };
  EXPECT_GE(placed(square(20, 200, 80, 260)).min.x(), 80) << "most room on the right";
  EXPECT_LE(placed(square(560, 200, 620, 260)).max.x(), 560) << "most room on the left";
  EXPECT_GE(placed(square(300, 10, 360, 60)).min.y(), 60) << "most room below";
  EXPECT_LE(placed(square(300, 420, 360, 470)).max.y(), 420) << "most room above";
}

TEST(LabelPlacer, ApplicationPolicyIsUsedAndItsBadCandidatesSkipped) {
  const Polygon outer = square(200, 200, 300, 260);
  LabelPlacerOptions options{.screen = kScreen};
  options.policy = [](const Box&, const Vec2& s, const Box&, double) {
    return std::vector<Box>{box_at_corner(Vec2(250, 230), s),   // on the object: refused
                            box_at_corner(Vec2(700, 10), s),    // off screen: refused
                            box_at_corner(Vec2(10, 400), s)};   // free: used
  };
  const LabelRequest request{{}, outer, Vec2(50, 20)};
  const auto labels = place_labels(std::span(&request, 1), options);
  EXPECT_EQ(labels[0].placement, LabelPlacement::outside_outer);
  EXPECT_TRUE(labels[0].box.min.isApprox(Vec2(10, 400)));
}

TEST(LabelPlacer, OutsideLabelsPreferPlacesThatHideNoOtherObject) {
  const Polygon a = square(200, 200, 260, 240), b = square(270, 205, 330, 235);
  const std::vector<LabelRequest> requests = {{{}, a, Vec2(60, 20)}, {{}, b, Vec2(60, 20)}};
  const auto spared = place_labels(requests, {.screen = kScreen});
  ASSERT_EQ(spared[0].placement, LabelPlacement::outside_outer);
  EXPECT_EQ(shared_area(spared[0].box, b), 0) << "a's label leaves b visible";
  EXPECT_EQ(shared_area(spared[1].box, a), 0);
  expect_no_overlaps(spared);
  // Without the preference the first candidate (right of a) is taken although it hides b.
  const auto plain = place_labels(requests, {.screen = kScreen, .avoid_other_objects = false});
  EXPECT_GT(shared_area(plain[0].box, b), 0);
  EXPECT_EQ(shared_area(plain[0].box, a), 0);
}

TEST(LabelPlacer, NeverInsideWhenTheApplicationForbidsCoveringObjects) {
  const Polygon outer = square(100, 100, 300, 250), inner = square(130, 130, 270, 220);
  const LabelRequest request{inner, outer, Vec2(40, 20)};
  const auto labels =
      place_labels(std::span(&request, 1), {.screen = kScreen, .allow_inside = false});
  EXPECT_EQ(labels[0].placement, LabelPlacement::outside_outer);
  EXPECT_EQ(shared_area(labels[0].box, outer), 0);
}

TEST(LabelPlacer, ObjectsWithoutRegionsGoToTheCornerListTopToBottom) {
  const double nan = std::nan("");
  const std::vector<LabelRequest> requests = {
      {{}, {}, Vec2(80, 20)},                                              // no region
      {{}, {Vec2(nan, 0), Vec2(1, 0), Vec2(0, 1)}, Vec2(60, 20)},        // non-finite region
      {{}, {}, Vec2(nan, 20)},                                             // bad size
  };
  const auto labels = place_labels(requests, {.screen = kScreen, .gap_px = 4});
  for (const PlacedLabel& l : labels) {
    EXPECT_EQ(l.placement, LabelPlacement::corner_list);
    EXPECT_FALSE(l.anchored);
    EXPECT_FALSE(l.leader);
    EXPECT_TRUE(l.on_screen);
  }
  EXPECT_TRUE(labels[0].box.min.isApprox(Vec2(4, 4)));
  EXPECT_TRUE(labels[1].box.min.isApprox(Vec2(4, 28)));
  EXPECT_NEAR(labels[2].box.width(), 0, 1e-12);
  expect_no_overlaps(labels);
}

TEST(SpaceManager, StepsOverOccupiedBoxesAndStartsNewColumns) {
  const Box screen{Vec2(0, 0), Vec2(200, 100)};
  const Box occupied[] = {box_at_corner(Vec2(0, 30), Vec2(50, 20))};
  const std::vector<Vec2> sizes(6, Vec2(40, 20));
  const auto boxes = stack_in_corner(sizes, occupied, screen, 5);
  ASSERT_EQ(boxes.size(), 6u);
  EXPECT_TRUE(boxes[0].min.isApprox(Vec2(5, 5)));
  EXPECT_TRUE(boxes[1].min.isApprox(Vec2(5, 55))) << "below the occupied box";
  EXPECT_TRUE(boxes[2].min.isApprox(Vec2(5, 80))) << "ends exactly at the bottom";
  EXPECT_TRUE(boxes[3].min.isApprox(Vec2(50, 5))) << "next column";
  EXPECT_TRUE(boxes[5].min.isApprox(Vec2(50, 55)));
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_FALSE(boxes_overlap(boxes[i], occupied[0])) << i;
    for (std::size_t j = i + 1; j < boxes.size(); ++j) EXPECT_FALSE(boxes_overlap(boxes[i], boxes[j]));
    EXPECT_TRUE(box_inside(boxes[i], screen)) << i;
  }
}

// The separating-axis test the placer asks of every candidate place, in both forms,
// against the area that clipping cuts out: a box that shares area meets the polygon, and
// one that stays clear of it by more than a rounding does not. Grid polygons put many
// boxes exactly along an edge.
TEST(BoxMeetsConvex, AgreesWithClippingInBothForms) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 200), size(0.5, 60);
  int met = 0, clear = 0;
  ConvexSides sides;
  for (int trial = 0; trial < 4000; ++trial) {
    const Polygon convex = widget_testing::random_convex(rng, Vec2(100, 100), 60, 12, trial % 2);
    convex_sides(convex, sides);
    Vec2 corner(u(rng), u(rng));
    if (trial % 2) corner = corner.array().round().matrix();
    const Box box = box_at_corner(corner, Vec2(size(rng), size(rng)).array().round().max(1).matrix());
    const bool meets = box_meets_convex(box, convex);
    ASSERT_EQ(meets, box_meets_convex(box, sides)) << trial;
    const Box grown{box.min - Vec2::Constant(1e-3), box.max + Vec2::Constant(1e-3)};
    if (shared_area(box, convex) > 1e-6) {
      EXPECT_TRUE(meets) << trial;
      ++met;
    } else if (shared_area(grown, convex) == 0) {
      EXPECT_FALSE(meets) << trial;
      ++clear;
    }
  }
  EXPECT_GT(met, 1000);
  EXPECT_GT(clear, 1000);
}

TEST(LabelPlacer, RandomScenesKeepEveryConstraint) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> ux(0, 640), uy(0, 480), usize(10, 90), shrink(0.2, 0.9);
  std::uniform_int_distribution<int> count(1, 30);
  int inside = 0, outside = 0, listed = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<LabelRequest> requests;
    for (int i = 0, n = count(rng); i < n; ++i) {
      LabelRequest r;
      r.outer = widget_testing::random_convex(rng, Vec2(ux(rng), uy(rng)), 10 + trial % 120);
      if (i % 5 != 4) r.inner = shrunk(r.outer, shrink(rng));
      if (i % 11 == 10) r.outer.clear(), r.inner.clear();
      r.size_px = Vec2(usize(rng), usize(rng) / 3);
      requests.push_back(r);
    }
    LabelPlacerOptions options{.screen = kScreen};
    if (trial % 2) options.policy = most_free_space_policy();
    const auto labels = place_labels(requests, options);
    ASSERT_EQ(labels.size(), requests.size());
    expect_no_overlaps(labels);
    for (std::size_t i = 0; i < labels.size(); ++i) {
      const PlacedLabel& l = labels[i];
      EXPECT_NEAR(l.box.width(), requests[i].size_px.x(), 1e-9);
      EXPECT_NEAR(l.box.height(), requests[i].size_px.y(), 1e-9);
      EXPECT_EQ(l.on_screen, box_inside(l.box, kScreen, 1e-6));
      switch (l.placement) {
        case LabelPlacement::inside_inner:
          ++inside;
          EXPECT_TRUE(corners_inside(l.box, requests[i].inner)) << trial << "/" << i;
          EXPECT_TRUE(l.on_screen);
          break;
        case LabelPlacement::outside_outer:
          ++outside;
          EXPECT_LT(shared_area(l.box, requests[i].outer), 1e-6) << trial << "/" << i;
          EXPECT_TRUE(l.on_screen);
          EXPECT_TRUE(l.leader);
          break;
        case LabelPlacement::corner_list:
          ++listed;
          EXPECT_FALSE(l.anchored);
          EXPECT_EQ(l.leader.has_value(), !requests[i].outer.empty());
          break;
      }
    }
  }
  // Each branch must have been exercised for the checks above to mean anything.
  EXPECT_GT(inside, 100);
  EXPECT_GT(outside, 100);
  EXPECT_GT(listed, 50);
}
