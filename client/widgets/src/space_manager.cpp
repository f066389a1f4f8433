#include "covtrack/client/space_manager.hpp"

#include <algorithm>
#include <cmath>

#include "corner_list.hpp"

namespace covtrack::client {

std::vector<Box> stack_in_corner(std::span<const Vec2> sizes, std::span<const Box> occupied,
                                 const Box& screen, double gap) {
  BoxGrid taken;
  std::vector<Box> placed;
  stack_in_corner(sizes, occupied, screen, gap, taken, placed);
  return placed;
}

void stack_in_corner(std::span<const Vec2> sizes, std::span<const Box> occupied, const Box& screen,
                     double gap, BoxGrid& taken, std::vector<Box>& placed) {
  placed.clear();
  // Cells about a label's size when the list is long.
  const auto boxes = static_cast<double>(occupied.size() + sizes.size());
  taken.reset(screen, std::clamp(static_cast<int>(std::sqrt(boxes)), 1, 64));
  // Below every occupied box and the screen, a box can only meet the list's own boxes,
  // and those of its column are above it and those of earlier columns to its left: there
  // nothing is looked up or filed (a list that outgrows the screen would otherwise pile
  // into the grid's bottom cells and be searched whole for every box).
  double floor_y = screen.max.y();
  for (const Box& box : occupied) taken.insert(box), floor_y = std::max(floor_y, box.max.y());
  gap = std::max(gap, 0.0);  // a negative gap could step back onto the same box forever
  const double top = screen.min.y() + gap;
  double x = screen.min.x() + gap, y = top, column_width = 0;
  for (const Vec2& size : sizes) {
    for (;;) {
      const Box box = box_at_corner(Vec2(x, y), size);
      const double next_x = x + column_width + gap;
      if (box.max.y() > screen.max.y() && y > top && column_width > 0 &&
          next_x + size.x() <= screen.max.x()) {
        x = next_x, y = top, column_width = 0;  // next column
        continue;
      }
      // Step below the lowest box in the way (each step moves down: this ends).
      double below = y;
      const bool past_floor = box.min.y() >= floor_y;
      if (!past_floor)
        taken.any_near(box, [&](std::size_t i) {
          const Box& other = taken.boxes()[i];
          if (boxes_overlap(box, other)) below = std::max(below, other.max.y() + gap);
          return false;  // every box in the way counts
        });
      if (below > y) {
        y = below;
        continue;
      }
      placed.push_back(box);
      if (!past_floor) taken.insert(box);
      y = box.max.y() + gap;
      column_width = std::max(column_width, size.x());
      break;
    }
  }
}

}  // namespace covtrack::client
