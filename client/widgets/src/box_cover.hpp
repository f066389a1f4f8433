#pragma once
// A fine raster over an area (the screen) whose cells each name one filed box that meets
// the cell. It answers "does this box overlap a filed box?" at once for the usual case
// that it does: the label placer's candidate places on a crowded screen (at 1,000 objects
// 9 in 10 overlap a label already placed), where a grid search per candidate was most of
// the placer's time. A corner of the asked box lies in a cell; the box that cell names is
// tested exactly, so a yes is always right. A no only means that none of those tests hit:
// the caller then asks the grid (box_grid.hpp).
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "covtrack/client/screen_box.hpp"

namespace covtrack::client {

class BoxCover {
 public:
  // Empties the raster and lays it over `area` (cells of about kCellPx, at most
  // kMaxCellsAcross along a side), keeping its memory. A non-finite area has no raster:
  // every answer is then no.
  void reset(const Box& area);
  // Files the box in the cells it meets (the last one filed there wins).
  void insert(const Box& box);

  // A box filed in the cell of one of box's corners overlaps box. Always inlined: asked
  // of every candidate place, whose finiteness the caller has just checked too.
  [[gnu::always_inline]] bool overlap_at_corners(const Box& box) const {
    if (cells_.empty() || !box.min.allFinite() || !box.max.allFinite()) return false;
    const int x0 = column(box.min.x()), x1 = column(box.max.x());
    const int y0 = row(box.min.y()), y1 = row(box.max.y());
    const Index* top = cells_.data() + y0 * across_x_;
    const Index* bottom = cells_.data() + y1 * across_x_;
    // All four tested, without branches: which corner hits is unpredictable, and an empty
    // cell names the box that overlaps nothing.
    const auto overlaps = [&](Index i) {
      const Box& b = boxes_[i];
      return (box.min.x() < b.max.x()) & (b.min.x() < box.max.x()) & (box.min.y() < b.max.y()) &
             (b.min.y() < box.max.y());
    };
    return overlaps(top[x0]) | overlaps(top[x1]) | overlaps(bottom[x0]) | overlaps(bottom[x1]);
  }

  static constexpr double kCellPx = 8;
  static constexpr int kMaxCellsAcross = 128;

 private:
  // Clamped in double before the conversion (a far-off coordinate would overflow an int);
  // by max and min rather than std::clamp, which branches (finite coordinates only).
  int column(double x) const { return static_cast<int>(std::min(std::max((x - origin_.x()) * per_px_.x(), 0.0), max_x_)); }
  int row(double y) const { return static_cast<int>(std::min(std::max((y - origin_.y()) * per_px_.y(), 0.0), max_y_)); }

  Vec2 origin_ = Vec2::Zero(), per_px_ = Vec2::Ones();
  int across_x_ = 0, across_y_ = 0;
  double max_x_ = 0, max_y_ = 0;  // across - 1
  // Two bytes a cell keep the raster small enough to stay in the nearest cache; the boxes
  // filed after the first 65,535 are not named in it (the grid still has them).
  using Index = std::uint16_t;
  std::vector<Index> cells_;  // row by row: an index into boxes_
  std::vector<Box> boxes_;             // [0]: NaN, overlapping nothing; then as filed
  // The cell ranges written since the last reset, cleared by the next one: a frame's few
  // labels, not the whole raster.
  struct Range {
    int x0, x1, y0, y1;
  };
  std::vector<Range> written_;
};

}  // namespace covtrack::client
