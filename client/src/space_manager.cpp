#include "covtrack/client/space_manager.hpp"

#include <algorithm>

namespace covtrack::client {

std::vector<Box> stack_in_corner(std::span<const Vec2> sizes, std::span<const Box> occupied,
                                 const Box& screen, double gap) {
  std::vector<Box> placed;
  std::vector<Box> taken(occupied.begin(), occupied.end());
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
      for (const Box& other : taken)
        if (boxes_overlap(box, other)) below = std::max(below, other.max.y() + gap);
      if (below > y) {
        y = below;
        continue;
      }
      placed.push_back(box);
      taken.push_back(box);
      y = box.max.y() + gap;
      column_width = std::max(column_width, size.x());
      break;
    }
  }
  return placed;
}

}  // namespace covtrack::client
