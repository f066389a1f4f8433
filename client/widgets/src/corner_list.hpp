#pragma once
// stack_in_corner (space_manager.hpp) with its memory lent by the caller: the label placer
// lists labels every frame, and a fresh grid per frame was an allocation per cell touched.
#include <span>
#include <vector>

#include "box_grid.hpp"
#include "covtrack/client/screen_box.hpp"

namespace covtrack::client {

// The same boxes as stack_in_corner, into `placed` (resized); `taken` is the grid it
// files boxes in (reset here).
void stack_in_corner(std::span<const Vec2> sizes_px, std::span<const Box> occupied, const Box& screen,
                     double gap_px, BoxGrid& taken, std::vector<Box>& placed);

}  // namespace covtrack::client
