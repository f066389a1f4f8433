#pragma once
// The space manager's list (dissertation 5.6.4, docs/background.md): labels the label
// placer could not anchor to their object go into a list in the screen's top-left corner,
// top to bottom, then in further columns to the right when the screen's height runs out.
// Boxes already on the screen are stepped over, so the list never overlaps them nor itself.
#include <span>
#include <vector>

#include "covtrack/client/screen_box.hpp"

namespace covtrack::client {

// One box per size, in order. A box that does not fit on the screen any more goes below
// the last column (off screen, still overlapping nothing).
std::vector<Box> stack_in_corner(std::span<const Vec2> sizes_px, std::span<const Box> occupied,
                                 const Box& screen, double gap_px);

}  // namespace covtrack::client
