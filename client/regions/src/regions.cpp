#include <algorithm>
#include <cmath>
#include <limits>

#include "covtrack/client/regions.hpp"
#include "regions_from_tangents.hpp"

namespace covtrack::client {

namespace {

// The region when it is the polygon of consecutive lines' corners: each line's normal turns
// left of the one before by less than pi (so, in all, once round) and each line keeps an
// edge of positive length between its corners with the lines before and after. Then that
// polygon is convex with an edge on every line, so it is their intersection, found without
// clipping. False otherwise (an empty or degenerate region, or a line that cuts off no
// edge): the caller clips.
bool corners_of_consecutive_lines(std::span<const TangentLine> lines, Polygon& region) {
  const std::size_t k = lines.size();
  region.resize(k);
  for (std::size_t i = 0; i < k; ++i) {
    const TangentLine &a = lines[i], &b = lines[i + 1 == k ? 0 : i + 1];
    if (!(cross(a.normal, b.normal) > 0)) return false;
    region[i] = corner(a.normal, a.offset, b.normal, b.offset);  // line i's end, the next one's start
  }
  for (std::size_t i = 0; i < k; ++i) {
    const Vec2 edge = region[i] - region[i == 0 ? k - 1 : i - 1];
    if (!(cross(lines[i].normal, edge) > 0)) return false;  // along (-n_y, n_x)
  }
  return true;
}

// The general way: a box well around the hull, cut down by each half-plane in turn. Each
// cut adds at most one corner, so two buffers of 4 + k corners hold every step (kept per
// thread: no allocation per object).
void clip_box(std::span<const ProjectedVertex> hull, std::span<const TangentLine> lines,
              Polygon& inner) {
  const std::size_t k = lines.size();
  Eigen::AlignedBox2d box;
  for (const ProjectedVertex& v : hull) box.extend(v.mean_px);
  const double margin = box.diagonal().norm() + 1.0;
  thread_local std::vector<Vec2> buffers;
  buffers.resize(2 * (4 + k));
  Vec2* region = buffers.data();
  Vec2* next = region + 4 + k;
  region[0] = box.min() - Vec2(margin, margin);
  region[1] = Vec2(box.max().x() + margin, box.min().y() - margin);
  region[2] = box.max() + Vec2(margin, margin);
  region[3] = Vec2(box.min().x() - margin, box.max().y() + margin);
  std::size_t size = 4;
  for (std::size_t i = 0; i < k && size > 0; ++i) {
    size = clip_half_plane(std::span<const Vec2>(region, size), lines[i].normal, lines[i].offset, next);
    std::swap(region, next);
  }
  inner.assign(region, region + size);
}

}  // namespace

void contract_region(std::span<const ProjectedVertex> hull, std::span<const TangentLine> inner_lines,
                     Polygon& inner) {
  inner.clear();
  if (hull.size() < 3) return;  // a point or a segment has no interior to keep
  if (!corners_of_consecutive_lines(inner_lines, inner)) clip_box(hull, inner_lines, inner);
  // A sliver left by rounding is no region.
  if (inner.size() < 3 || polygon_area(inner) <= 1e-9) inner.clear();
}

void contract_region(std::span<const ProjectedVertex> hull, const RegionOptions& o,
                     Polygon& inner) {
  // One line per hull edge, tangent to the ellipses at its ends (region_tangents.hpp).
  thread_local std::vector<TangentLine> lines;
  hull_tangents(hull.size(), [&](std::size_t i) -> const ProjectedVertex& { return hull[i]; },
                std::pow(confidence_scale(o.confidence), 2), &lines, nullptr);
  contract_region(hull, lines, inner);
}

Polygon contract_region(std::span<const ProjectedVertex> hull, const RegionOptions& o) {
  Polygon inner;
  contract_region(hull, o, inner);
  return inner;
}

}  // namespace covtrack::client
