// Selection: likelihoods on hand-made polygons with known areas, direct, indirect (targets
// spread by the pointer's error, hit one at a time) and two-step selection.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "covtrack/client/convex_polygon.hpp"
#include "covtrack/client/selection.hpp"
#include "covtrack/client/selection_session.hpp"
#include "widget_polygons.hpp"

using namespace covtrack::client;
using covtrack::client::widget_testing::square;

namespace {
Pointer square_pointer(const Vec2& at, double half) {
  return {at, square(at.x() - half, at.y() - half, at.x() + half, at.y() + half)};
}
}  // namespace

TEST(SelectionLikelihood, ByAreaOnHandMadePolygons) {
  const Pointer pointer = square_pointer(Vec2(5, 5), 5);  // [0,10]^2, area 100
  const double nan = std::nan("");
  const std::vector<Selectable> objects = {
      {square(5, 0, 15, 10)},                          // half of the pointer
      {square(-100, -100, 100, 100)},                  // all of it
      {{Vec2(0, 0), Vec2(10, 0), Vec2(0, 10)}},        // a triangle over half
      {square(2, 2, 4, 3)},                            // 2 of 100 px
      {square(20, 20, 30, 30)},                        // apart
      {{}},                                            // no region
      {{Vec2(nan, 0), Vec2(10, 0), Vec2(0, 10)}},      // non-finite
  };
  const auto l = likelihoods_by_area(pointer, objects);
  ASSERT_EQ(l.size(), objects.size());
  EXPECT_NEAR(l[0], 0.5, 1e-12);
  EXPECT_NEAR(l[1], 1.0, 1e-12);
  EXPECT_NEAR(l[2], 0.5, 1e-12);
  EXPECT_NEAR(l[3], 0.02, 1e-12);
  EXPECT_EQ(l[4], 0);
  EXPECT_EQ(l[5], 0);
  EXPECT_EQ(l[6], 0);
}

TEST(SelectionLikelihood, APointPointerGivesContainment) {
  const Pointer point{Vec2(3, 3), {}};
  const std::vector<Selectable> objects = {{square(0, 0, 10, 10)}, {square(5, 5, 10, 10)}};
  const auto l = likelihoods_by_area(point, objects);
  EXPECT_EQ(l[0], 1);
  EXPECT_EQ(l[1], 0);
}

TEST(SelectionLikelihood, ByDistanceFallsLinearlyToTheRegionsRadius) {
  const std::vector<Selectable> objects = {{square(-10, -10, 10, 10)}, {square(100, 0, 110, 10)}};
  const double radius = 10 * std::sqrt(2.0);
  for (double d : {0.0, 5.0, 10.0, 14.0, 20.0}) {
    const auto l = likelihoods_by_distance(Pointer{Vec2(d, 0), {}}, objects);
    EXPECT_NEAR(l[0], std::max(0.0, 1 - d / radius), 1e-12) << d;
    EXPECT_EQ(l[1], 0) << d;
  }
  const double nan = std::nan("");
  EXPECT_EQ(likelihoods_by_distance(Pointer{Vec2(nan, 0), {}}, objects)[0], 0);
}

TEST(SelectionLikelihood, MatchesTheFractionOfPointerSamplesOnTheObject) {
  // The area ratio is the chance that a uniform pixel of the pointer falls on the object.
  std::mt19937_64 rng(8);
  const Pointer pointer = pointer_with_covariance(Vec2(50, 50), (Mat2() << 90, 30, 30, 40).finished());
  const Box bounds = bounding_box(pointer.region);
  std::uniform_real_distribution<double> ux(bounds.min.x(), bounds.max.x()), uy(bounds.min.y(), bounds.max.y());
  const std::vector<Selectable> objects = {{{Vec2(40, 30), Vec2(70, 45), Vec2(45, 70)}}};
  const double l = likelihoods_by_area(pointer, objects)[0];
  int in_pointer = 0, on_both = 0;
  for (int k = 0; k < 400000; ++k) {
    const Vec2 q(ux(rng), uy(rng));
    if (!polygon_contains(pointer.region, q)) continue;
    ++in_pointer;
    on_both += polygon_contains(objects[0].region, q);
  }
  const double fraction = static_cast<double>(on_both) / in_pointer;
  EXPECT_GT(l, 0.1);
  EXPECT_LT(l, 0.9);
  EXPECT_NEAR(l, fraction, 4 * std::sqrt(fraction * (1 - fraction) / in_pointer));
}

TEST(SelectionPointer, FromAProjectedTipItsEllipseOrLost) {
  ProjectedVertex tip;
  tip.mean_px = Vec2(100, 50);
  tip.covariance_px2 << 16, 0, 0, 4;  // sigmas 4 and 2 px
  const Pointer p = pointer_from_projection(tip, 0.95, 32);
  EXPECT_FALSE(p.lost);
  // The 95% ellipse's semi-major axis is 4 * 2.4477 px; the 32-gon holds it and adds < 0.5%.
  EXPECT_GE(pointer_error_px(p), 4 * confidence_scale(0.95) - 1e-9);
  EXPECT_LE(pointer_error_px(p), 4 * confidence_scale(0.95) / std::cos(3.14159265358979 / 32) + 1e-9);
  EXPECT_TRUE(polygon_contains(p.region, Vec2(100 + 4 * 2.4, 50)));
  EXPECT_FALSE(polygon_contains(p.region, Vec2(100, 50 + 2 * 2.5)));
  tip.flags.unbounded = true;  // a LOST pose
  EXPECT_TRUE(pointer_from_projection(tip).lost);
}

TEST(DirectSelection, MostLikelyFirstThenNearest) {
  const std::vector<Selectable> objects = {{{}, 3.0}, {{}, 1.0}, {{}, 2.0}, {{}, 0.5}};
  const std::vector<double> likelihoods = {0.4, 0.4, 0.9, 0.0};
  const DirectSelection d = select_direct(likelihoods, objects, 0.0);
  EXPECT_EQ(d.candidates, (std::vector<int>{2, 1, 0}));
  EXPECT_EQ(d.selected, 2);
  EXPECT_TRUE(d.ambiguous());
  const DirectSelection strict = select_direct(likelihoods, objects, 0.5);
  EXPECT_EQ(strict.candidates, (std::vector<int>{2}));
  EXPECT_FALSE(strict.ambiguous());
  EXPECT_FALSE(select_direct(std::vector<double>{0, 0}, objects, 0).selected);
}

TEST(IndirectSelection, TargetsAreSpreadByThePointersErrorAndHitOneAtATime) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> count(2, 14);
  const IndirectOptions options{.target_size_px = Vec2(50, 20), .screen = {Vec2(0, 0), Vec2(640, 480)}};
  for (int trial = 0; trial < 40; ++trial) {
    Mat2 B;
    B << 8 * u(rng), 8 * u(rng), 8 * u(rng), 8 * u(rng);
    const Pointer pointer = pointer_with_covariance(Vec2(320 + 300 * u(rng), 240 + 200 * u(rng)),
                                                    B * B.transpose() + Mat2::Identity());
    const double error = pointer_error_px(pointer);
    std::vector<int> objects;
    for (int i = 0, n = count(rng); i < n; ++i) objects.push_back(10 * i);
    const auto targets = layout_indirect_targets(objects, pointer, options);
    ASSERT_EQ(targets.size(), objects.size());
    // Every pair: separated along x or y by at least the pointer's error (in fact twice it).
    for (std::size_t i = 0; i < targets.size(); ++i)
      for (std::size_t j = i + 1; j < targets.size(); ++j) {
        const Box &a = targets[i].box, &b = targets[j].box;
        const double gap_x = std::max(b.min.x() - a.max.x(), a.min.x() - b.max.x());
        const double gap_y = std::max(b.min.y() - a.max.y(), a.min.y() - b.max.y());
        EXPECT_GE(std::max(gap_x, gap_y), 2 * error) << "trial " << trial;
      }
    // Aiming at a target's centre hits that target, however the error is shaped.
    for (const SelectionTarget& t : targets) {
      Pointer aimed = pointer;
      const Vec2 shift = t.box.center() - pointer.position_px;
      aimed.position_px += shift;
      for (Vec2& v : aimed.region) v += shift;
      EXPECT_EQ(hit_target(targets, aimed), t.object) << "trial " << trial;
    }
    // Anywhere: the pointer's region never meets two targets.
    const Box& first = targets.front().box;
    for (double x = first.min.x() - 60; x < first.min.x() + 700; x += 4)
      for (double y = first.min.y() - 60; y < first.min.y() + 300; y += 4) {
        Pointer moved = pointer;
        const Vec2 shift = Vec2(x, y) - pointer.position_px;
        moved.position_px += shift;
        for (Vec2& v : moved.region) v += shift;
        int met = 0;
        for (const SelectionTarget& t : targets) met += box_meets_convex(t.box, moved.region);
        ASSERT_LE(met, 1) << "trial " << trial << " at " << x << ", " << y;
      }
  }
}

TEST(IndirectSelection, SpreadGrowsWithThePointersErrorAndStaysOnScreen) {
  const IndirectOptions options{.target_size_px = Vec2(40, 20), .screen = {Vec2(0, 0), Vec2(640, 480)}};
  const std::vector<int> objects = {1, 2, 3};
  double last_spacing = 0;
  for (double sigma : {1.0, 5.0, 20.0}) {
    const Pointer p = pointer_with_covariance(Vec2(320, 240), Mat2::Identity() * sigma * sigma);
    const auto targets = layout_indirect_targets(objects, p, options);
    const double spacing = targets[1].box.min.x() - targets[0].box.max.x();
    EXPECT_GT(spacing, last_spacing) << sigma;
    last_spacing = spacing;
    for (const SelectionTarget& t : targets) EXPECT_TRUE(box_inside(t.box, options.screen, 1e-9));
  }
  // Near the screen's corner the row is moved onto the screen.
  const Pointer corner = pointer_with_covariance(Vec2(5, 5), Mat2::Identity() * 9);
  for (const SelectionTarget& t : layout_indirect_targets(objects, corner, options))
    EXPECT_TRUE(box_inside(t.box, options.screen, 1e-9));
  // Without a bound on the pointer's error no layout can be unambiguous.
  const Pointer lost = pointer_with_covariance(Vec2(5, 5), Mat2::Identity() * std::nan(""));
  EXPECT_TRUE(lost.lost);
  EXPECT_TRUE(std::isinf(pointer_error_px(lost)));
  EXPECT_TRUE(layout_indirect_targets(objects, lost, options).empty());
  const std::vector<Selectable> everywhere = {{{Vec2(-1e6, -1e6), Vec2(1e6, -1e6), Vec2(0, 1e6)}}};
  EXPECT_EQ(likelihoods_by_area(lost, everywhere)[0], 0);
  EXPECT_EQ(likelihoods_by_distance(lost, everywhere)[0], 0);
}

TEST(TwoStepSelection, NarrowsByLikelihoodThenPicksATarget) {
  // Three drawers under the pointer's region, one far away.
  const std::vector<Selectable> drawers = {
      {square(100, 100, 200, 130), 1.0}, {square(100, 130, 200, 160), 1.0},
      {square(100, 160, 200, 190), 1.0}, {square(400, 300, 500, 330), 1.0}};
  TwoStepSelection selection({.min_likelihood = 0.0,
                              .indirect = {.target_size_px = Vec2(40, 20),
                                           .screen = {Vec2(0, 0), Vec2(640, 480)}}});
  const Pointer wide = pointer_with_covariance(Vec2(150, 145), Mat2::Identity() * 400);
  EXPECT_FALSE(selection.click(wide, drawers));
  ASSERT_EQ(selection.step(), TwoStepSelection::Step::pick_object);
  ASSERT_EQ(selection.targets().size(), 3u);
  // The second target, whatever its order.
  const SelectionTarget chosen = selection.targets()[1];
  const Pointer on_target = pointer_with_covariance(chosen.box.center(), Mat2::Identity() * 400);
  EXPECT_EQ(selection.click(on_target, drawers), chosen.object);
  EXPECT_EQ(selection.step(), TwoStepSelection::Step::pick_group);
  // A precise pointer on one drawer selects it at once.
  const Pointer precise = pointer_with_covariance(Vec2(450, 315), Mat2::Identity() * 4);
  EXPECT_EQ(selection.click(precise, drawers), 3);
  // A click beside every target cancels the second step.
  EXPECT_FALSE(selection.click(wide, drawers));
  ASSERT_EQ(selection.step(), TwoStepSelection::Step::pick_object);
  EXPECT_FALSE(selection.click(pointer_with_covariance(Vec2(600, 450), Mat2::Identity()), drawers));
  EXPECT_EQ(selection.step(), TwoStepSelection::Step::pick_group);
}

// The session a user drives: preselection names what a direct click would pick; direct
// clicks select at once; two-step lays out targets for an ambiguous click and the next
// click on a target selects; switching technique drops the targets.
TEST(SelectionSession, PreselectsClicksAndSwitchesTechnique) {
  const std::vector<Selectable> objects = {{square(0, 0, 10, 10), 1.0}, {square(9, 0, 19, 10), 2.0},
                                           {square(40, 40, 50, 50), 1.5}};
  const auto at = [](double u, double v) { return pointer_with_covariance(Vec2(u, v), Mat2::Identity() * 0.25); };
  SelectionSession session;
  EXPECT_EQ(session.technique(), SelectionTechnique::two_step);
  session.update(at(45, 45), objects);
  EXPECT_EQ(session.preselected(), 2);
  session.set_preselect(false);
  session.update(at(45, 45), objects);
  EXPECT_FALSE(session.preselected());

  EXPECT_EQ(session.click(at(45, 45), objects), 2);
  EXPECT_EQ(session.selected(), 2);
  EXPECT_FALSE(session.click(at(9.5, 5), objects)) << "two candidates: targets first";
  ASSERT_EQ(session.targets().size(), 2u);
  EXPECT_EQ(session.selected(), 2) << "still the last selection";
  const SelectionTarget second = session.targets()[1];
  EXPECT_EQ(session.click(at(second.box.center().x(), second.box.center().y()), objects), second.object);
  EXPECT_TRUE(session.targets().empty());

  EXPECT_FALSE(session.click(at(9.5, 5), objects));
  ASSERT_FALSE(session.targets().empty());
  session.set_technique(SelectionTechnique::direct);
  EXPECT_TRUE(session.targets().empty()) << "switching drops the other technique's targets";
  EXPECT_EQ(session.click(at(9.3, 5), objects), 0) << "direct: the more likely at once";
  EXPECT_FALSE(session.click(at(100, 100), objects));
  EXPECT_EQ(session.selected(), 0);
}
