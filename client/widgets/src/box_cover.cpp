#include "box_cover.hpp"

#include <cmath>
#include <limits>

namespace covtrack::client {

void BoxCover::reset(const Box& area) {
  const auto across = [](double extent) {
    return static_cast<int>(std::clamp(std::ceil(extent / kCellPx), 1.0, double(kMaxCellsAcross)));
  };
  const bool finite = area.min.allFinite() && area.max.allFinite();
  const int ax = finite ? across(area.width()) : 0, ay = finite ? across(area.height()) : 0;
  if (ax != across_x_ || ay != across_y_) {
    across_x_ = ax, across_y_ = ay;
    cells_.assign(static_cast<std::size_t>(ax * ay), 0);
  } else {
    for (const Range& r : written_)
      for (int y = r.y0; y <= r.y1; ++y)
        std::fill_n(cells_.begin() + y * across_x_ + r.x0, r.x1 - r.x0 + 1, 0);
  }
  written_.clear();
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  boxes_.assign(1, Box{Vec2(nan, nan), Vec2(nan, nan)});
  if (!finite) return;
  const Vec2 size = (area.max - area.min).cwiseMax(1.0);  // a degenerate area is one cell wide
  origin_ = area.min;
  per_px_ = Vec2(ax / size.x(), ay / size.y());
  max_x_ = ax - 1, max_y_ = ay - 1;
}

void BoxCover::insert(const Box& box) {
  if (cells_.empty() || !box.min.allFinite() || !box.max.allFinite() ||
      boxes_.size() > std::numeric_limits<Index>::max())
    return;
  const auto index = static_cast<Index>(boxes_.size());
  boxes_.push_back(box);
  const Range r{column(box.min.x()), column(box.max.x()), row(box.min.y()), row(box.max.y())};
  for (int y = r.y0; y <= r.y1; ++y) std::fill_n(cells_.begin() + y * across_x_ + r.x0, r.x1 - r.x0 + 1, index);
  written_.push_back(r);
}

}  // namespace covtrack::client
