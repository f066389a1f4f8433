// The grid the label placer and the space manager find nearby boxes with: what it returns
// against testing every box, for boxes on, across and far off its area and non-finite
// ones; and a corner list far longer than the screen, whose boxes below the screen are
// not filed, against every box it must stay clear of.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "box_grid.hpp"
#include "covtrack/client/space_manager.hpp"

using namespace covtrack;
using namespace covtrack::client;

namespace {

Box random_box(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> at(-200, 840), size(0, 120);
  std::uniform_int_distribution<int> kind(0, 19);
  const int k = kind(rng);
  if (k == 0) return {Vec2(1e12, 5), Vec2(1e12 + 10, 15)};  // far off, beyond any int
  if (k == 1) return {Vec2(std::numeric_limits<double>::quiet_NaN(), 0), Vec2(10, 10)};
  if (k == 2) return {Vec2(-std::numeric_limits<double>::infinity(), 0), Vec2(10, 10)};
  const Vec2 min(at(rng), at(rng));
  return {min, min + Vec2(size(rng), size(rng))};
}

}  // namespace

TEST(BoxGrid, FindsEveryOverlappingBoxOnceAndStopsWhenAsked) {
  std::mt19937_64 rng(21);
  const Box screen{Vec2(0, 0), Vec2(640, 480)};
  for (int cells : {1, 7, 32}) {
    BoxGrid grid(screen, cells);
    for (int i = 0; i < 400; ++i) grid.insert(random_box(rng));
    for (int q = 0; q < 400; ++q) {
      const Box query = random_box(rng);
      std::multiset<std::size_t> visited;
      EXPECT_FALSE(grid.any_near(query, [&](std::size_t i) { return visited.insert(i), false; }));
      for (std::size_t i = 0; i < grid.boxes().size(); ++i) {
        if (boxes_overlap(query, grid.boxes()[i])) {
          EXPECT_EQ(visited.count(i), 1u) << "cells " << cells << " box " << i;
        }
        EXPECT_LE(visited.count(i), 1u);
      }
      int calls = 0;
      const bool stopped = grid.any_near(query, [&](std::size_t) { return ++calls, true; });
      EXPECT_EQ(stopped, !visited.empty());
      EXPECT_LE(calls, 1);
    }
  }
}

TEST(SpaceManager, AListLongerThanTheScreenStaysClearOfEveryBox) {
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> width(20, 90), height(8, 25), at(0, 600);
  const Box screen{Vec2(0, 0), Vec2(640, 480)};
  std::vector<Box> occupied;
  for (int i = 0; i < 60; ++i) occupied.push_back(box_at_corner(Vec2(at(rng), at(rng)), Vec2(width(rng), height(rng))));
  occupied.push_back(box_at_corner(Vec2(5, 900), Vec2(200, 40)));  // below the screen, where the list goes
  std::vector<Vec2> sizes;
  for (int i = 0; i < 700; ++i) sizes.emplace_back(width(rng), height(rng));
  const std::vector<Box> list = stack_in_corner(sizes, occupied, screen, 3);
  ASSERT_EQ(list.size(), sizes.size());
  int below = 0;
  for (std::size_t i = 0; i < list.size(); ++i) {
    below += list[i].min.y() >= screen.max.y();
    for (const Box& o : occupied) ASSERT_FALSE(boxes_overlap(list[i], o)) << "list box " << i;
    for (std::size_t j = i + 1; j < list.size(); ++j) ASSERT_FALSE(boxes_overlap(list[i], list[j])) << i << " " << j;
  }
  EXPECT_GT(below, 100) << "the list must outgrow the screen for this test to mean much";
}
