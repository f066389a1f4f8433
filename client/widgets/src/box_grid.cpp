#include "box_grid.hpp"

#include <algorithm>
#include <cmath>

namespace covtrack::client {

BoxGrid::BoxGrid(const Box& area, int cells_across) : origin_(area.min) {
  const int n = std::max(cells_across, 1);
  const Vec2 size = (area.max - area.min).cwiseMax(1.0);  // a degenerate area is one cell wide
  const bool finite = area.min.allFinite() && area.max.allFinite();
  across_x_ = finite ? n : 1, across_y_ = finite ? n : 1;
  cell_ = finite ? Vec2(size.x() / n, size.y() / n) : Vec2(1, 1);
  if (!finite) origin_ = Vec2::Zero();
  cells_.resize(static_cast<std::size_t>(across_x_ * across_y_));
}

BoxGrid::Range BoxGrid::cells_of(const Box& box) const {
  if (!box.min.allFinite() || !box.max.allFinite()) return {0, across_x_ - 1, 0, across_y_ - 1};
  // Clamped in double before the conversion: a box far off screen would overflow an int.
  const auto cell = [](double at, double origin, double width, int across) {
    return static_cast<int>(std::clamp(std::floor((at - origin) / width), 0.0, double(across - 1)));
  };
  return {cell(box.min.x(), origin_.x(), cell_.x(), across_x_), cell(box.max.x(), origin_.x(), cell_.x(), across_x_),
          cell(box.min.y(), origin_.y(), cell_.y(), across_y_), cell(box.max.y(), origin_.y(), cell_.y(), across_y_)};
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
