#include "covtrack/client/label_placer.hpp"

#include <algorithm>
#include <cmath>

#include "box_cover.hpp"
#include "box_grid.hpp"
#include "corner_list.hpp"
#include "covtrack/client/convex_polygon.hpp"
#include "covtrack/client/space_manager.hpp"

namespace covtrack::client {
namespace {

// Sub-pixel slack for rounding in the clipped feasible polygon.
constexpr double kInsideTolerancePx = 1e-6;

bool box_inside_convex(const Box& box, const Polygon& convex) {
  for (const Vec2& corner : box_polygon(box))
    if (!polygon_contains(convex, corner, kInsideTolerancePx)) return false;
  return true;
}

// The labels placed so far: filed in a grid for the exact test, and in a raster that
// rejects most overlapping candidates with one box test (box_cover.hpp).
struct PlacedBoxes {
  BoxGrid grid;
  BoxCover cover;

  void reset(const Box& screen, int cells) {
    grid.reset(screen, cells);
    cover.reset(screen);
  }
  void insert(const Box& box) {
    cover.insert(box);
    grid.insert(box);
  }
  [[gnu::always_inline]] bool clear_of(const Box& box) const {
    if (cover.overlap_at_corners(box)) return false;
    return !grid.any_near(box, [&](std::size_t i) { return boxes_overlap(box, grid.boxes()[i]); });
  }
};

// A box of `size` could lie within `bounds` (up to the containment tests' tolerance).
bool could_hold(const Box& bounds, const Vec2& size) {
  constexpr double kSlackPx = 1e-3;
  return size.x() <= bounds.width() + kSlackPx && size.y() <= bounds.height() + kSlackPx;
}

Vec2 sane_size(const Vec2& size) {
  return {std::isfinite(size.x()) ? std::max(size.x(), 0.0) : 0.0,
          std::isfinite(size.y()) ? std::max(size.y(), 0.0) : 0.0};
}

// The centres of feasible_label_centers, for a region known to be usable, into `centers`
// (`scratch` holds the clipping's steps): no allocation per label once they have grown.
void centers_within(const Polygon& region, const Vec2& size, const Box& screen, Polygon& centers,
                    Polygon& scratch);

std::optional<Box> place_inside(const Polygon& inner, const Vec2& size, const Box& screen,
                                const PlacedBoxes& placed, Polygon& centers, Polygon& scratch) {
  centers_within(inner, size, screen, centers, scratch);
  if (centers.empty()) return std::nullopt;
  // The middle of the feasible centres first (the label sits well inside), then its
  // corners, which move the label as far as it can go when another label is in the way.
  const auto fits = [&](const Box& box) {
    return box_inside_convex(box, inner) && box_inside(box, screen, kInsideTolerancePx) && placed.clear_of(box);
  };
  if (const Box box = box_at_center(polygon_centroid(centers), size); fits(box)) return box;
  for (const Vec2& c : centers)
    if (const Box box = box_at_center(c, size); fits(box)) return box;
  return std::nullopt;
}

// Objects' outer regions (their requests' indices), filed by their bounding boxes.
struct Obstacles {
  std::vector<std::size_t> request;
  BoxGrid bounds;
};

// The outer regions readied for box tests (convex_sides), each when first tested: a
// region is tested by many candidate places (its own label's, its neighbours'), and most
// regions of a crowded screen by none.
struct OuterSides {
  std::span<const LabelRequest> requests;
  std::vector<ConvexSides> sides;  // its memory kept from call to call
  std::vector<bool> ready;

  void reset(std::span<const LabelRequest> r) {
    requests = r;
    if (sides.size() < r.size()) sides.resize(r.size());
    ready.assign(r.size(), false);
  }
  const ConvexSides& of(std::size_t i) {
    if (!ready[i]) convex_sides(requests[i].outer, sides[i]), ready[i] = true;
    return sides[i];
  }
};

// Polygon i of a request, usable or not, told once per call: the checks read every vertex.
struct Usable {
  bool inner = false, outer = false;
};

// The label of request i.
std::optional<Box> place_outside(std::size_t i, const Box& outer_bounds, const Vec2& size,
                                 const LabelPlacerOptions& o, const PlacedBoxes& placed,
                                 const Obstacles& objects, OuterSides& outer) {
  if (!o.policy) return std::nullopt;
  const std::vector<Box> candidates = o.policy(outer_bounds, size, o.screen, o.gap_px);
  const auto hides_another = [&](const Box& box) {
    return o.avoid_other_objects && objects.bounds.any_near(box, [&](std::size_t k) {
      const std::size_t j = objects.request[k];
      return j != i && boxes_overlap(box, objects.bounds.boxes()[k]) && box_meets_convex(box, outer.of(j));
    });
  };
  // The first place that hides no other object either; failing that, the first one
  // clear of its own object.
  std::optional<Box> fallback;
  for (const Box& box : candidates) {
    if (!(box.min.allFinite() && box.max.allFinite() && box_inside(box, o.screen) &&
          placed.clear_of(box) && !(boxes_overlap(box, outer_bounds) && box_meets_convex(box, outer.of(i)))))
      continue;
    if (!hides_another(box)) return box;
    if (!fallback) fallback = box;
  }
  return fallback;
}

std::array<Vec2, 2> leader_to(const Box& box, const Polygon& region) {
  const Vec2 object = polygon_centroid(region);
  return {nearest_point_on_box(box, object), object};
}

}  // namespace

Polygon feasible_label_centers(const Polygon& region, const Vec2& size, const Box& screen) {
  if (!is_usable_polygon(region)) return {};
  Polygon centers, scratch;
  centers_within(region, size, screen, centers, scratch);
  return centers;
}

namespace {
void centers_within(const Polygon& region, const Vec2& size, const Box& screen, Polygon& centers,
                    Polygon& scratch) {
  const Vec2 half = 0.5 * size;
  // Each clip writes at most two points per edge (one for a convex region).
  const auto clip = [&](const Vec2& normal, double offset) {
    scratch.resize(2 * centers.size());
    scratch.resize(clip_half_plane(centers, normal, offset, scratch.data()));
    centers.swap(scratch);
  };
  centers.assign(region.begin(), region.end());
  for (std::size_t i = 0, n = region.size(); i < n && !centers.empty(); ++i) {
    const Vec2 e = region[(i + 1) % n] - region[i];
    if (e.squaredNorm() == 0) continue;
    const Vec2 outward = Vec2(e.y(), -e.x()).normalized();
    // The box corner farthest along the outward normal must stay behind the edge.
    const double reach = std::abs(outward.x()) * half.x() + std::abs(outward.y()) * half.y();
    clip(outward, outward.dot(region[i]) - reach);
  }
  const std::array<std::pair<Vec2, double>, 4> screen_sides = {{
      {Vec2(-1, 0), -(screen.min.x() + half.x())},
      {Vec2(1, 0), screen.max.x() - half.x()},
      {Vec2(0, -1), -(screen.min.y() + half.y())},
      {Vec2(0, 1), screen.max.y() - half.y()},
  }};
  for (const auto& [normal, offset] : screen_sides)
    if (!centers.empty()) clip(normal, offset);
}
}  // namespace

struct LabelPlacer::Workspace {
  PlacedBoxes placed;
  Obstacles objects;
  std::vector<Usable> usable;
  std::vector<Box> outer_bounds;  // of the usable outer regions
  Polygon centers, scratch;
  OuterSides outer_sides;
  std::vector<std::size_t> rest;
  std::vector<Vec2> sizes;
  BoxGrid list_grid;
  std::vector<Box> list;
};

LabelPlacer::LabelPlacer() : work_(std::make_unique<Workspace>()) {}
LabelPlacer::~LabelPlacer() = default;
LabelPlacer::LabelPlacer(LabelPlacer&&) noexcept = default;
LabelPlacer& LabelPlacer::operator=(LabelPlacer&&) noexcept = default;

void LabelPlacer::place(std::span<const LabelRequest> requests, const LabelPlacerOptions& o,
                        std::vector<PlacedLabel>& labels) {
  Workspace& w = *work_;
  const std::size_t n = requests.size();
  labels.assign(n, PlacedLabel{});
  w.usable.resize(n);
  w.outer_bounds.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    w.usable[i] = {is_usable_polygon(requests[i].inner), is_usable_polygon(requests[i].outer)};
    if (w.usable[i].outer) w.outer_bounds[i] = bounding_box(requests[i].outer);
  }
  // Cells about the size of a label when the screen is full of objects.
  const int cells = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(n))), 1, 64);
  PlacedBoxes& placed = w.placed;
  placed.reset(o.screen, cells);
  // A label is placed when it is anchored (inside or outside); the rest go to the list.
  // Inside labels first: they are the most constrained, and an outside label must not
  // take the space an inner region offers.
  if (o.allow_inside) {
    for (std::size_t i = 0; i < n; ++i) {
      if (!w.usable[i].inner) continue;
      const Vec2 size = sane_size(requests[i].size_px);
      // A box inside the region is inside its bounding box: most inner regions of a
      // crowded screen are smaller than a label, and clipping them would tell the same.
      if (!could_hold(bounding_box(requests[i].inner), size)) continue;
      if (auto box = place_inside(requests[i].inner, size, o.screen, placed, w.centers, w.scratch)) {
        labels[i] = {*box, LabelPlacement::inside_inner, true, std::nullopt, true};
        placed.insert(*box);
      }
    }
  }
  w.outer_sides.reset(requests);
  Obstacles& objects = w.objects;
  objects.request.clear();
  objects.bounds.reset(o.screen, std::max(cells / 2, 1));
  if (o.avoid_other_objects && o.policy)  // only outside places are tested against them
    for (std::size_t i = 0; i < n; ++i)
      if (w.usable[i].outer)
        objects.request.push_back(i), objects.bounds.insert(w.outer_bounds[i]);
  for (std::size_t i = 0; i < n; ++i) {
    if (labels[i].anchored || !w.usable[i].outer) continue;
    const Vec2 size = sane_size(requests[i].size_px);
    if (auto box = place_outside(i, w.outer_bounds[i], size, o, placed, objects, w.outer_sides)) {
      labels[i] = {*box, LabelPlacement::outside_outer, true, leader_to(*box, requests[i].outer),
                   true};
      placed.insert(*box);
    }
  }
  w.rest.clear();
  w.sizes.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (!labels[i].anchored) w.rest.push_back(i), w.sizes.push_back(sane_size(requests[i].size_px));
  stack_in_corner(w.sizes, placed.grid.boxes(), o.screen, o.gap_px, w.list_grid, w.list);
  const std::vector<Box>& list = w.list;
  for (std::size_t k = 0; k < w.rest.size(); ++k) {
    PlacedLabel& label = labels[w.rest[k]];
    label.box = list[k];
    label.placement = LabelPlacement::corner_list;
    label.anchored = false;
    if (w.usable[w.rest[k]].outer) label.leader = leader_to(list[k], requests[w.rest[k]].outer);
    label.on_screen = box_inside(list[k], o.screen);
  }
}

std::vector<PlacedLabel> place_labels(std::span<const LabelRequest> requests,
                                      const LabelPlacerOptions& o) {
  std::vector<PlacedLabel> labels;
  LabelPlacer().place(requests, o, labels);
  return labels;
}

}  // namespace covtrack::client
