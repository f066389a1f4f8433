#pragma once
// Boxes filed in a uniform grid over an area (the screen), so that the boxes near a given
// box are found without testing every one: the label placer asks this for every candidate
// place of every label, against every label placed and every object on screen, which was
// quadratic in the number of objects.
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "covtrack/client/screen_box.hpp"

namespace covtrack::client {

class BoxGrid {
 public:
  // About `cells_across` cells along each side of `area`. Boxes reaching beyond the area
  // are filed in its border cells; a box with a non-finite side is near every box.
  BoxGrid(const Box& area, int cells_across);
  BoxGrid() : BoxGrid(Box{}, 1) {}

  // Empties the grid and lays it over a new area, keeping its memory: a caller that files
  // boxes every frame (the label placer) then allocates nothing once the counts settle.
  void reset(const Box& area, int cells_across);

  // Files `box` under the next index (0, 1, ...).
  void insert(const Box& box);
  std::span<const Box> boxes() const { return boxes_; }

  // Calls hit(i) once for each filed box i in the cells `box` covers (a superset of the
  // boxes that overlap it), until one returns true; whether one did.
  template <class Hit>
  bool any_near(const Box& box, Hit&& hit) const {
    const Range r = cells_of(box);
    ++visit_;
    for (int y = r.y0; y <= r.y1; ++y)
      for (int x = r.x0; x <= r.x1; ++x)
        for (std::uint32_t i : cells_[static_cast<std::size_t>(y * across_x_ + x)])
          if (seen_[i] != visit_) {
            seen_[i] = visit_;
            if (hit(static_cast<std::size_t>(i))) return true;
          }
    return false;
  }

 private:
  struct Range {
    int x0, x1, y0, y1;
  };
  // Inline: asked once per candidate label place.
  Range cells_of(const Box& box) const {
    if (!box.min.allFinite() || !box.max.allFinite()) return {0, across_x_ - 1, 0, across_y_ - 1};
    // Clamped in double before the conversion: a box far off screen would overflow an int.
    // On the clamped, non-negative value the conversion's truncation is the floor, without
    // a call to floor.
    const auto cell = [](double at, double origin, double per_px, int across) {
      return static_cast<int>(std::clamp((at - origin) * per_px, 0.0, double(across - 1)));
    };
    return {cell(box.min.x(), origin_.x(), per_px_.x(), across_x_), cell(box.max.x(), origin_.x(), per_px_.x(), across_x_),
            cell(box.min.y(), origin_.y(), per_px_.y(), across_y_), cell(box.max.y(), origin_.y(), per_px_.y(), across_y_)};
  }

  // Cells per pixel: a cell index is a multiplication, not a division. Any cell function
  // that never decreases along an axis finds every overlapping box, so this one finds the
  // same boxes as any other.
  Vec2 origin_, per_px_;
  int across_x_, across_y_;
  std::vector<Box> boxes_;
  std::vector<std::vector<std::uint32_t>> cells_;
  mutable std::vector<std::uint64_t> seen_;  // per box: the last visit that met it
  mutable std::uint64_t visit_ = 0;
};

}  // namespace covtrack::client
