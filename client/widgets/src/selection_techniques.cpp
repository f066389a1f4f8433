#include <algorithm>
#include <cmath>

#include "covtrack/client/selection.hpp"

namespace covtrack::client {

DirectSelection select_direct(std::span<const double> likelihoods,
                              std::span<const Selectable> objects, double min_likelihood) {
  DirectSelection d;
  for (std::size_t i = 0; i < likelihoods.size(); ++i)
    if (likelihoods[i] > min_likelihood) d.candidates.push_back(static_cast<int>(i));
  const auto depth = [&](int i) {
    return static_cast<std::size_t>(i) < objects.size() ? objects[static_cast<std::size_t>(i)].depth_m
                                                        : 0.0;
  };
  std::stable_sort(d.candidates.begin(), d.candidates.end(), [&](int a, int b) {
    const double la = likelihoods[static_cast<std::size_t>(a)];
    const double lb = likelihoods[static_cast<std::size_t>(b)];
    return la > lb || (la == lb && depth(a) < depth(b));
  });
  if (!d.candidates.empty()) d.selected = d.candidates.front();
  return d;
}

double indirect_target_spacing_px(const Pointer& pointer, const IndirectOptions& o) {
  // The region lies within the error of the position, so its extent in any direction is
  // at most twice the error: a gap that wide cannot be bridged by one pointer region.
  return 2 * pointer_error_px(pointer) + std::max(o.margin_px, 0.0);
}

std::vector<SelectionTarget> layout_indirect_targets(std::span<const int> objects,
                                                     const Pointer& pointer,
                                                     const IndirectOptions& o) {
  std::vector<SelectionTarget> targets;
  if (objects.empty()) return targets;
  const double gap = indirect_target_spacing_px(pointer, o);
  if (!std::isfinite(gap) || !o.target_size_px.allFinite()) return targets;  // cannot be spread
  const Vec2 size = o.target_size_px.cwiseMax(Vec2::Zero());
  const Vec2 pitch = size + Vec2(gap, gap);
  const double n = static_cast<double>(objects.size());
  const double per_row_fit = std::floor((o.screen.width() + gap) / pitch.x());
  const double per_row = std::clamp(per_row_fit, 1.0, n);
  const double rows = std::ceil(n / per_row);
  const Vec2 grid(per_row * pitch.x() - gap, rows * pitch.y() - gap);
  // Centred above the pointer's region, clear of it by one gap, then onto the screen.
  const Box reach = box_at_center(pointer.position_px, Vec2::Constant(2 * pointer_error_px(pointer)));
  Vec2 corner(pointer.position_px.x() - grid.x() / 2, reach.min.y() - gap - grid.y());
  corner.x() = std::clamp(corner.x(), o.screen.min.x(), std::max(o.screen.min.x(), o.screen.max.x() - grid.x()));
  corner.y() = std::clamp(corner.y(), o.screen.min.y(), std::max(o.screen.min.y(), o.screen.max.y() - grid.y()));
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const double row = std::floor(static_cast<double>(k) / per_row);
    const double column = static_cast<double>(k) - row * per_row;
    targets.push_back({objects[k], box_at_corner(corner + Vec2(column * pitch.x(), row * pitch.y()), size)});
  }
  return targets;
}

std::optional<int> hit_target(std::span<const SelectionTarget> targets, const Pointer& pointer) {
  if (pointer.lost) return std::nullopt;
  std::optional<int> hit;
  int hits = 0;
  for (const SelectionTarget& t : targets) {
    const bool meets = pointer.region.size() >= 3
                           ? box_meets_convex(t.box, pointer.region)
                           : box_inside(Box{pointer.position_px, pointer.position_px}, t.box, 0);
    if (meets) hit = t.object, ++hits;
  }
  return hits == 1 ? hit : std::nullopt;
}

std::optional<int> TwoStepSelection::click(const Pointer& pointer,
                                           std::span<const Selectable> objects) {
  if (step_ == Step::pick_object) {
    std::optional<int> chosen = hit_target(targets_, pointer);
    bool meets_any = false;
    for (const SelectionTarget& t : targets_)
      meets_any = meets_any || (pointer.region.size() >= 3 && box_meets_convex(t.box, pointer.region));
    if (chosen || !meets_any) {  // a choice, or a click beside every target: back to step 1
      step_ = Step::pick_group;
      targets_.clear();
    }
    return chosen;
  }
  const DirectSelection direct =
      select_direct(likelihoods_by_area(pointer, objects), objects, options_.min_likelihood);
  if (direct.candidates.size() == 1) return direct.selected;
  if (direct.ambiguous()) {
    targets_ = layout_indirect_targets(direct.candidates, pointer, options_.indirect);
    if (!targets_.empty()) step_ = Step::pick_object;
  }
  return std::nullopt;
}

}  // namespace covtrack::client
