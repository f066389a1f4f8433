#pragma once
// Selection under uncertainty (dissertation chapter 6, docs/background.md). The pointer has
// its own error: its region is a convex polygon around its position. Each object's region
// (normally its outer region) gets a likelihood of being the one meant:
//  - by area (6.5.1): area(pointer ∩ object) / area(pointer), the chance that a pixel of
//    the pointer falls on the object, both uniform; the intersection is linear-time;
//  - by distance (6.5.2): max(0, 1 - |pointer - object centre| / object radius).
// Techniques (6.6): direct selection (the most likely, nearer first on ties); indirect
// selection (one on-screen target per candidate, spread by the pointer's error so that
// each can be hit alone); two-step selection (direct to narrow down, then indirect).
#include <optional>
#include <span>
#include <vector>

#include "covtrack/client/regions.hpp"
#include "covtrack/client/screen_box.hpp"

namespace covtrack::client {

struct Pointer {
  Vec2 position_px = Vec2::Zero();
  Polygon region;  // convex, counter-clockwise, holds position_px
  // Error unbounded (LOST, non-finite covariance): it points nowhere in particular, so
  // every likelihood is 0 and no target can be hit.
  bool lost = false;
};

// A pointer whose position has a 2x2 covariance (px^2): its region is the `confidence`
// ellipse, circumscribed by a `sides`-gon (so it holds the ellipse).
Pointer pointer_with_covariance(const Vec2& position_px, const Mat2& covariance_px2,
                                double confidence = 0.95, int sides = 16);

// A tracked 3-D pointer (e.g. a stylus tip) projected with project_vertex: its pixel and
// pixel covariance; lost when the projection is unusable (LOST pose, behind the camera).
Pointer pointer_from_projection(const ProjectedVertex& tip, double confidence = 0.95,
                                int sides = 16);

// How far the pointer can be off: the largest distance from its position to its region's
// boundary. 0 for a region-less pointer; +inf when lost or the region is not finite.
double pointer_error_px(const Pointer& pointer);

struct Selectable {
  Polygon region;      // convex; empty or non-finite: cannot be selected (likelihood 0)
  double depth_m = 0;  // distance from the camera, breaks ties (nearer first)
};

// An object selected by its outer region (where it can be on the screen), at the mean
// depth of its vertices.
Selectable selectable_of(const ObjectRegions& regions);

// A pointer without area (a point) gives 1 inside the region and 0 outside.
std::vector<double> likelihoods_by_area(const Pointer& pointer, std::span<const Selectable> objects);
std::vector<double> likelihoods_by_distance(const Pointer& pointer,
                                            std::span<const Selectable> objects);

struct DirectSelection {
  // Every object with likelihood > min_likelihood, most likely first, then nearest.
  std::vector<int> candidates;
  std::optional<int> selected;  // candidates.front(), if any
  bool ambiguous() const { return candidates.size() > 1; }
};
DirectSelection select_direct(std::span<const double> likelihoods,
                              std::span<const Selectable> objects, double min_likelihood = 0);

struct SelectionTarget {
  int object = 0;
  Box box;
};

struct IndirectOptions {
  Vec2 target_size_px{60, 24};
  Box screen{Vec2(0, 0), Vec2(640, 480)};
  double margin_px = 2;  // on top of the spacing the pointer's error needs
};

// Targets in rows above the pointer (wrapped to the screen's width), moved onto the
// screen when they fit. Neighbouring targets are 2 * pointer_error_px + margin apart, so
// the pointer's region (within pointer_error_px of its position) meets at most one.
std::vector<SelectionTarget> layout_indirect_targets(std::span<const int> objects,
                                                     const Pointer& pointer,
                                                     const IndirectOptions& options = {});
// The spacing that layout uses for this pointer.
double indirect_target_spacing_px(const Pointer& pointer, const IndirectOptions& options = {});

// The object of the one target the pointer's region meets; none if it meets none or
// (the pointer's error grew since the layout) several.
std::optional<int> hit_target(std::span<const SelectionTarget> targets, const Pointer& pointer);

// Two-step selection (6.6.3) as a small state machine driven by clicks.
class TwoStepSelection {
 public:
  enum class Step { pick_group, pick_object };
  struct Options {
    double min_likelihood = 0;  // by area
    IndirectOptions indirect;
  };
  explicit TwoStepSelection(Options options) : options_(std::move(options)) {}

  // pick_group: a click on a single candidate selects it; on several lays out their
  // targets and moves to pick_object. pick_object: a click on one target selects its
  // object and returns to pick_group; a click on no target cancels back to pick_group;
  // a click on several keeps waiting.
  std::optional<int> click(const Pointer& pointer, std::span<const Selectable> objects);

  Step step() const { return step_; }
  const std::vector<SelectionTarget>& targets() const { return targets_; }

 private:
  Options options_;
  Step step_ = Step::pick_group;
  std::vector<SelectionTarget> targets_;
};

}  // namespace covtrack::client
