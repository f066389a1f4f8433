#pragma once
// The slow, obvious intersection of two convex polygons, as the reference the library's
// linear-time intersect_convex and the label placer are checked against.
#include "covtrack/client/regions.hpp"

namespace covtrack::client::reference {

// `a` clipped by every edge's half-plane of `b` (both counter-clockwise): O(n m). Empty
// when either has fewer than 3 vertices or they do not meet. Unlike intersect_convex it
// may keep repeated or collinear vertices; areas and containment are unaffected.
inline Polygon intersect_convex_by_clipping(const Polygon& a, const Polygon& b) {
  if (a.size() < 3 || b.size() < 3) return {};
  Polygon out = a;
  for (std::size_t i = 0, n = b.size(); i < n && !out.empty(); ++i) {
    const Vec2 e = b[(i + 1) % n] - b[i];
    const Vec2 outward(e.y(), -e.x());  // counter-clockwise: the interior is on the left
    out = clip_half_plane(out, outward, outward.dot(b[i]));
  }
  return out;
}

}  // namespace covtrack::client::reference
