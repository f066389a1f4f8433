#include "box_grid.hpp"

#include <algorithm>
#include <cmath>

namespace covtrack::client {

BoxGrid::BoxGrid(const Box& area, int cells_across) { reset(area, cells_across); }

void BoxGrid::reset(const Box& area, int cells_across) {
  const int n = std::max(cells_across, 1);
  const Vec2 size = (area.max - area.min).cwiseMax(1.0);  // a degenerate area is one cell wide
  const bool finite = area.min.allFinite() && area.max.allFinite();
  across_x_ = finite ? n : 1, across_y_ = finite ? n : 1;
  per_px_ = finite ? Vec2(n / size.x(), n / size.y()) : Vec2(1, 1);
  origin_ = finite ? area.min : Vec2::Zero();
  boxes_.clear();
  seen_.clear();
  visit_ = 0;
  for (auto& cell : cells_) cell.clear();
  cells_.resize(static_cast<std::size_t>(across_x_ * across_y_));
}

void BoxGrid::insert(const Box& box) {
  const auto index = static_cast<std::uint32_t>(boxes_.size());
  boxes_.push_back(box);
  seen_.push_back(0);
  const Range r = cells_of(box);
  for (int y = r.y0; y <= r.y1; ++y)
    for (int x = r.x0; x <= r.x1; ++x) cells_[static_cast<std::size_t>(y * across_x_ + x)].push_back(index);
}

}  // namespace covtrack::client
