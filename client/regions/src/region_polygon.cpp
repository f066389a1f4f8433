#include <algorithm>
#include <cstdint>
#include <cstring>
#include <numeric>

#include "covtrack/client/regions.hpp"
#include "plane_cross.hpp"
#include "vector_clones.hpp"

namespace covtrack::client {
namespace {
// Up to this many points (an object's box) take the hull by successors below.
constexpr int kFewPoints = 8;

// Vectors of 4 (AVX2 registers). GCC 12 splits comparisons of vectors wider than the
// clone's registers into scalars: of 8 even with AVX-512, of 4 in the baseline clone (which
// therefore sorts instead, see convex_hull_indices). Of 2 it was 5% slower with AVX2.
using Lanes = DoubleLanes4;
using Mask = MaskLanes4;
constexpr int kGroups = kFewPoints / 4;

// For every point i at once (the lanes), the point j seen from i farthest clockwise, and of
// those in line the farthest away: from a hull vertex that is the next one counter-clockwise
// (every point lies left of or on the line to it). No sort and no branches, where sorting
// and the chain's pops mispredicted on almost every comparison. Written with vector types:
// as loops over arrays the running choice went through memory (masked stores).
COVTRACK_VECTOR_CLONES
void hull_successors(const double (&px)[kFewPoints], const double (&py)[kFewPoints], int n,
                     std::int64_t (&successor)[kFewPoints]) {
  // Inside, so that it is compiled (and inlined) for the clone's instructions. (A cast
  // between vector types of one size keeps the bits.)
  const auto take = [](Lanes& value, const Mask& where, const Lanes& new_value) {
    value = (Lanes)(((Mask)new_value & where) | ((Mask)value & ~where));
  };
  Lanes x[kGroups], y[kGroups], bx[kGroups], by[kGroups], bd[kGroups];
  Mask next[kGroups];
  const Lanes zero = {};
  for (int g = 0; g < kGroups; ++g) {
    std::memcpy(&x[g], px + 4 * g, sizeof(Lanes));
    std::memcpy(&y[g], py + 4 * g, sizeof(Lanes));
    bx[g] = x[g], by[g] = y[g], bd[g] = zero;
    next[g] = Mask{0, 1, 2, 3} + 4 * g;
  }
  for (int j = 0; j < n; ++j) {
    const Lanes xj = zero + px[j], yj = zero + py[j];
#pragma GCC unroll 2
    for (int g = 0; g < kGroups; ++g) {
      const Lanes dx = xj - x[g], dy = yj - y[g];
      const Lanes turn = (bx[g] - x[g]) * dy - (by[g] - y[g]) * dx, d = dx * dx + dy * dy;
      const Mask better = (turn < zero) | ((turn == zero) & (d > bd[g]));
      take(bx[g], better, xj), take(by[g], better, yj), take(bd[g], better, d);
      next[g] = ((Mask{} + j) & better) | (next[g] & ~better);
    }
  }
  for (int g = 0; g < kGroups; ++g) std::memcpy(successor + 4 * g, &next[g], sizeof(Mask));
}

// The hull of 3 to kFewPoints points as convex_hull_indices gives it; false where rounding
// made the successors inconsistent (the caller then sorts).
bool few_points_hull(std::span<const Vec2> p, std::vector<int>& h) {
  const int n = static_cast<int>(p.size());
  double x[kFewPoints], y[kFewPoints];
  int start = 0;
  for (int i = 0; i < kFewPoints; ++i) {
    const Vec2& q = p[i < n ? i : 0];  // the padding repeats point 0 and is never followed
    x[i] = q.x(), y[i] = q.y();
    if (i < n && (q.x() < x[start] || (q.x() == x[start] && q.y() < y[start]))) start = i;
  }
  std::int64_t next[kFewPoints];
  hull_successors(x, y, n, next);
  h.clear();
  int i = start;
  do {
    h.push_back(i);
    i = static_cast<int>(next[i]);
  } while (i != start && static_cast<int>(h.size()) < n);
  return i == start;
}
}  // namespace

void convex_hull_indices(std::span<const Vec2> p, std::vector<int>& h) {
  const int n = static_cast<int>(p.size());
  if (n >= 3 && n <= kFewPoints && vector_clones_have_avx2() && few_points_hull(p, h)) return;
  thread_local std::vector<int> idx;  // kept per thread: no allocation per object
  idx.resize(n);
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](int a, int b) {
    return p[a].x() < p[b].x() || (p[a].x() == p[b].x() && p[a].y() < p[b].y());
  });
  if (n < 3) {
    h.assign(idx.begin(), idx.end());
    if (n == 2 && p[idx[0]] == p[idx[1]]) h.pop_back();
    return;
  }
  h.resize(2 * n);
  int k = 0;
  for (int i = 0; i < n; ++i) {  // lower chain
    while (k >= 2 && cross(p[h[k - 2]], p[h[k - 1]], p[idx[i]]) <= 0) --k;
    h[k++] = idx[i];
  }
  for (int i = n - 2, t = k + 1; i >= 0; --i) {  // upper chain
    while (k >= t && cross(p[h[k - 2]], p[h[k - 1]], p[idx[i]]) <= 0) --k;
    h[k++] = idx[i];
  }
  h.resize(std::max(k - 1, 1));
}

std::vector<int> convex_hull_indices(std::span<const Vec2> points) {
  std::vector<int> hull;
  convex_hull_indices(points, hull);
  return hull;
}

namespace {
// Akl-Toussaint: the points extreme in 8 directions span a convex polygon; nothing
// strictly inside it can be on the hull. For the outer region (hundreds of ellipse-polygon
// corners, most of them inside) this removes most points before the sort.
Polygon drop_points_inside_extremes(std::span<const Vec2> points) {
  const Vec2 dirs[8] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
  int best[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (int i = 1; i < static_cast<int>(points.size()); ++i)
    for (int k = 0; k < 8; ++k)
      if (dirs[k].dot(points[i]) > dirs[k].dot(points[best[k]])) best[k] = i;
  Polygon octagon;  // counter-clockwise, repeated corners removed
  for (int k = 0; k < 8; ++k)
    if (octagon.empty() || points[best[k]] != octagon.back()) octagon.push_back(points[best[k]]);
  while (octagon.size() > 1 && octagon.front() == octagon.back()) octagon.pop_back();
  Polygon kept;
  kept.reserve(points.size());
  const std::size_t m = octagon.size();
  for (const Vec2& q : points) {
    bool strictly_inside = m >= 3;
    for (std::size_t i = 0; i < m && strictly_inside; ++i)
      strictly_inside = cross(octagon[i], octagon[(i + 1) % m], q) > 0;
    if (!strictly_inside) kept.push_back(q);
  }
  return kept;
}
}  // namespace

Polygon convex_hull(std::span<const Vec2> points) {
  // The same monotone chain on the values: sorting points directly, not indices, is
  // what keeps the outer region cheap.
  Polygon p = points.size() > 32 ? drop_points_inside_extremes(points)
                                 : Polygon(points.begin(), points.end());
  std::sort(p.begin(), p.end(), [](const Vec2& a, const Vec2& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  const int n = static_cast<int>(p.size());
  if (n < 3) {
    if (n == 2 && p[0] == p[1]) p.pop_back();
    return p;
  }
  Polygon h(2 * n);
  int k = 0;
  for (int i = 0; i < n; ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (int i = n - 2, t = k + 1; i >= 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(std::max(k - 1, 1));
  return h;
}

std::size_t clip_half_plane(std::span<const Vec2> poly, const Vec2& normal, double offset,
                            Vec2* out) {
  std::size_t m = 0;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[i + 1 == n ? 0 : i + 1];
    const double da = normal.dot(a) - offset, db = normal.dot(b) - offset;
    if (da <= 0) out[m++] = a;
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) out[m++] = a + (da / (da - db)) * (b - a);
  }
  return m;
}

Polygon clip_half_plane(const Polygon& poly, const Vec2& normal, double offset) {
  // Each edge adds at most two points: room for any polygon, not only a convex one (a
  // convex one needs size + 1; a caller's non-convex polygon must not write past the end).
  Polygon out(2 * poly.size());
  out.resize(clip_half_plane(poly, normal, offset, out.data()));
  return out;
}

bool polygon_contains(const Polygon& poly, const Vec2& q, double tol) {
  const std::size_t n = poly.size();
  if (n < 3) return false;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = poly[i];
    const Vec2 e = poly[(i + 1) % n] - a;
    // Counter-clockwise: the interior is on the left of every edge.
    if ((e.x() * (q.y() - a.y()) - e.y() * (q.x() - a.x())) / e.norm() < -tol) return false;
  }
  return true;
}

double polygon_area(const Polygon& poly) {
  double twice = 0;
  for (std::size_t i = 0, n = poly.size(); i < n; ++i) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[(i + 1) % n];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * twice;
}

}  // namespace covtrack::client
