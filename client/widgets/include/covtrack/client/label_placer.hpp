#pragma once
// Label placer (dissertation 5.6.3-5.6.4, docs/background.md). Each object gets a label box
// of a given size:
//  1. inside its inner region when the box fits there entirely (the label is then surely
//     on the object), unless the application asked never to cover objects;
//  2. else outside its outer region (the label surely does not hide the object), at the
//     first candidate position of a placement policy that is on screen and free, with a
//     leader line to the object;
//  3. else (no usable region, or no free place) in the space manager's list in the
//     top-left corner; with a leader line when the object's region is known.
// Labels never overlap each other. Inside and outside labels are always fully on screen;
// only a list that outgrows the screen leaves it.
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "covtrack/client/screen_box.hpp"

namespace covtrack::client {

struct LabelRequest {
  Polygon inner;          // may be empty (error swamps the object)
  Polygon outer;          // empty when the object has no usable region
  Vec2 size_px{80, 20};   // width, height
};

enum class LabelPlacement { inside_inner, outside_outer, corner_list };

struct PlacedLabel {
  Box box;
  LabelPlacement placement = LabelPlacement::corner_list;
  // Placed by the label placer at its object (inside, outside); false for the list.
  bool anchored = false;
  // From the label box to the object's centre (outside and list labels of located objects).
  std::optional<std::array<Vec2, 2>> leader;
  bool on_screen = false;
};

// A placement policy: candidate label boxes outside the box `object_bounds` (the outer
// region's bounding box), best first. The placer takes the first that is on screen, clear
// of the outer region and of every label already placed (and, first, of other objects).
using LabelPolicy = std::function<std::vector<Box>(const Box& object_bounds, const Vec2& label_size,
                                                   const Box& screen, double gap_px)>;

// Sides ordered by free space between the object and the screen's edge, largest first.
LabelPolicy most_free_space_policy();
// Right, top, bottom, left, in that order.
LabelPolicy fixed_order_policy();

struct LabelPlacerOptions {
  Box screen{Vec2(0, 0), Vec2(640, 480)};
  bool allow_inside = true;  // false: never cover an object (outside or list only)
  LabelPolicy policy = fixed_order_policy();
  double gap_px = 4;  // between a label and its object's outer region, and in the list
  // Outside labels: prefer places that cover no other object's outer region either, and
  // only then fall back to places clear of their own object alone.
  bool avoid_other_objects = true;
};

// One label per request, same order.
std::vector<PlacedLabel> place_labels(std::span<const LabelRequest> requests,
                                      const LabelPlacerOptions& options = {});

// place_labels for a caller that places labels every frame (ArView): it keeps its working
// memory (the grids of placed labels and of objects) from one call to the next, so that
// it allocates next to nothing once the number of labels settles. Same labels.
class LabelPlacer {
 public:
  LabelPlacer();
  ~LabelPlacer();
  LabelPlacer(LabelPlacer&&) noexcept;
  LabelPlacer& operator=(LabelPlacer&&) noexcept;

  // Writes one label per request into `labels` (resized), same order.
  void place(std::span<const LabelRequest> requests, const LabelPlacerOptions& options,
             std::vector<PlacedLabel>& labels);

 private:
  struct Workspace;  // label_placer.cpp
  std::unique_ptr<Workspace> work_;
};

// Centres at which a box of `size` lies inside the convex `region` and inside `screen`:
// the region clipped by each edge moved inwards by the box's extent along its normal.
Polygon feasible_label_centers(const Polygon& region, const Vec2& size, const Box& screen);

}  // namespace covtrack::client
