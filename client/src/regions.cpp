#include <algorithm>
#include <cmath>
#include <limits>

#include "covtrack/client/regions.hpp"
#include "region_tangents.hpp"

namespace covtrack::client {

void contract_region(std::span<const ProjectedVertex> hull, const RegionOptions& o,
                     Polygon& inner) {
  inner.clear();
  const std::size_t k = hull.size();
  if (k < 3) return;  // a point or a segment has no interior to keep
  const double s2 = std::pow(confidence_scale(o.confidence), 2);

  // Start from a box well around the hull; the half-planes cut it down. Each cut adds at
  // most one corner, so two buffers of 4 + k corners hold every step (kept per thread: no
  // allocation per object).
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
  // One line per hull edge, tangent to the ellipses at its ends (region_tangents.hpp).
  TangentBlock block;
  for (std::size_t first = 0; first < k && size > 0; first += kTangentPairs) {
    const int count = static_cast<int>(std::min<std::size_t>(kTangentPairs, k - first));
    for (int j = 0; j < kTangentPairs; ++j) {  // a short block repeats its first edge
      const std::size_t i = first + (j < count ? j : 0);
      set_tangent_pair(block, j, hull[i], hull[(i + 1) % k], s2);
    }
    common_tangents(block, TangentSide::inner);
    for (int j = 0; j < count && size > 0; ++j) {
      size = clip_half_plane(std::span<const Vec2>(region, size), Vec2(block.nu[j], block.nv[j]),
                             block.offset[j], next);
      std::swap(region, next);
    }
  }
  // A sliver left by rounding is no region.
  if (size < 3) return;
  inner.assign(region, region + size);
  if (polygon_area(inner) <= 1e-9) inner.clear();
}

Polygon contract_region(std::span<const ProjectedVertex> hull, const RegionOptions& o) {
  Polygon inner;
  contract_region(hull, o, inner);
  return inner;
}

}  // namespace covtrack::client
