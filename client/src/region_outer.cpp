// The outer region as the polygon of support lines of the hull of the confidence
// ellipses: built from the mean hull's tangents and arcs where every check passes, else
// searched for and refined where it is loose (see regions.hpp for the guarantee).
#include <cmath>
#include <limits>
#include <numbers>

#include "covtrack/client/regions.hpp"
#include "region_tangents.hpp"
#include "vector_clones.hpp"

namespace covtrack::client {
namespace {

// A support line of the set: normal . x <= offset, touching it at `contact`.
struct SupportLine {
  Vec2 normal;  // unit
  double offset;
  Vec2 contact;
  std::size_t ellipse;  // the one touching
};

// The confidence ellipses as structure-of-arrays (centre u, v; shape = scale^2 times the
// covariance: xx, xy, yy), padded to whole blocks with copies of the first: a direction's
// supports are one loop that vectorises, square roots included (vector_clones.hpp). The
// buffers are kept per thread, so a frame of many objects allocates nothing.
class Ellipses {
 public:
  void assign(std::span<const ProjectedVertex> vertices, double scale2) {
    const std::size_t n = vertices.size();
    const std::size_t padded = (n + kBlock - 1) / kBlock * kBlock;
    for (auto* column : {&cu_, &cv_, &sxx_, &sxy_, &syy_, &h_}) column->resize(padded);
    for (std::size_t i = 0; i < padded; ++i) {
      const ProjectedVertex& v = vertices[i < n ? i : 0];
      const Mat2& C = v.covariance_px2;
      cu_[i] = v.mean_px.x(), cv_[i] = v.mean_px.y();
      sxx_[i] = scale2 * C(0, 0), sxy_[i] = scale2 * 0.5 * (C(0, 1) + C(1, 0));
      syy_[i] = scale2 * C(1, 1);
    }
  }

  SupportLine support(const Vec2& n) {
    // max over ellipse i of n . x = n . c_i + sqrt(n^T S_i n).
    const double x = n.x(), y = n.y(), xx = x * x, xy2 = 2 * x * y, yy = y * y;
    const std::size_t size = h_.size();
    const double *cu = cu_.data(), *cv = cv_.data(), *sxx = sxx_.data(), *sxy = sxy_.data(),
                 *syy = syy_.data();
    double* h = h_.data();
    for (std::size_t i = 0; i < size; ++i)
      h[i] = x * cu[i] + y * cv[i] + std::sqrt(std::max(xx * sxx[i] + xy2 * sxy[i] + yy * syy[i], 0.0));
    // Branch-free (conditional moves): which ellipse wins varies from call to call, and a
    // mispredicted branch per ellipse cost more than the supports themselves.
    double top = h[0];
    std::size_t best = 0;
    for (std::size_t i = 1; i < size; ++i) {
      const bool higher = h[i] > top;
      top = higher ? h[i] : top;
      best = higher ? i : best;
    }
    return {n, top, farthest_point(best, n), best};
  }

  // Whether every line n_j . x <= h_j holds every ellipse (to rounding). The loop runs over
  // the lines, one ellipse at a time, so that it vectorises (a maximum over the ellipses
  // would be a reduction, which does not). No square roots: with the room r = h + slack -
  // n . c left beyond the centre, the support n . c + sqrt(n'Sn) fits iff r >= 0 and
  // n'Sn <= r^2.
  bool hold_all(std::span<const double> nx, std::span<const double> ny, std::span<const double> h) {
    const std::size_t lines = h.size();
    limit_.resize(lines);
    worst_.assign(lines, -std::numeric_limits<double>::infinity());
    double *limit = limit_.data(), *worst = worst_.data();
    for (std::size_t j = 0; j < lines; ++j) limit[j] = h[j] + 1e-9 * (1 + std::abs(h[j]));
    for (std::size_t i = 0; i < cu_.size(); ++i) {
      const double u = cu_[i], v = cv_[i], xx = sxx_[i], xy = sxy_[i], yy = syy_[i];
      for (std::size_t j = 0; j < lines; ++j) {
        const double x = nx[j], y = ny[j];
        const double room = limit[j] - (x * u + y * v);
        const double spread2 = x * x * xx + 2 * x * y * xy + y * y * yy;
        worst[j] = std::max(worst[j], room < 0 ? 1.0 : spread2 - room * room);
      }
    }
    for (std::size_t j = 0; j < lines; ++j)
      if (worst[j] > 0) return false;
    return true;
  }

  // Ellipse i's centre.
  Vec2 centre(std::size_t i) const { return {cu_[i], cv_[i]}; }
  // Ellipse i's shape: xx, xy, yy.
  Vec3 shape(std::size_t i) const { return {sxx_[i], sxy_[i], syy_[i]}; }

  // The point of ellipse i farthest along n (any length): c + S n / sqrt(n^T S n).
  Vec2 farthest_point(std::size_t i, const Vec2& n) const {
    const Vec2 c(cu_[i], cv_[i]);
    const Vec2 Sn(sxx_[i] * n.x() + sxy_[i] * n.y(), sxy_[i] * n.x() + syy_[i] * n.y());
    const double r = std::sqrt(std::max(n.dot(Sn), 0.0));
    return r > 0 ? Vec2(c + Sn / r) : c;
  }

 private:
  static constexpr std::size_t kBlock = 8;
  std::vector<double> cu_, cv_, sxx_, sxy_, syy_, h_, limit_, worst_;
};

// The direction to split the gap between lines a and b: the normal of the chord between
// their contact points. When the contacts are on two different ellipses it converges to
// their common tangent at once (exactly, for points), where bisecting would only creep up
// on it. Bisects when the chord is degenerate or its normal is not inside the gap.
// Directions are unit vectors throughout: no trigonometry per split.
Vec2 split_direction(const SupportLine& a, const SupportLine& b) {
  const Vec2 chord = b.contact - a.contact;
  if (chord.squaredNorm() > 0) {
    const Vec2 outward = Vec2(chord.y(), -chord.x()).normalized();  // chord turned by -90 deg
    const double margin = 1e-3 * cross(a.normal, b.normal);
    if (cross(a.normal, outward) > margin && cross(outward, b.normal) > margin) return outward;
  }
  return (a.normal + b.normal).normalized();  // the bisector
}

double squared_distance_to_segment(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (q - (a + t * ab)).squaredNorm();
}

// A line of the shortcut below: normal . x <= offset.
struct ArcLine {
  Vec2 normal;
  double offset;
  std::size_t ellipse;  // of the arc this line starts or lies in
};

// The shortcut's lines as structure-of-arrays, each with the ellipse of its arc (centre u,
// v; shape xx, xy, yy): their supports and their corners' checks are loops over all lines
// that vectorise, where line after line would wait on a square root and two divisions each.
// Fixed arrays, so the compiler sees that they do not overlap; an object needing more lines
// goes to the search. Line size() repeats line 0: corner p (of lines p and p + 1) needs no
// wrap-around.
struct ShortcutLines {
  static constexpr std::size_t kMost = 64;
  double nx[kMost + 1], ny[kMost + 1], h[kMost + 1], u[kMost], v[kMost], xx[kMost], xy[kMost],
      yy[kMost], qx[kMost], qy[kMost], gap2[kMost];
  std::size_t count = 0;

  std::size_t size() const { return count; }
  // offset = -infinity: the line is a support of its own ellipse (see close_with_supports).
  // False when full.
  bool push(const Ellipses& ellipses, const Vec2& normal, double offset, std::size_t ellipse) {
    if (count == kMost) return false;
    const Vec3 S = ellipses.shape(ellipse);
    const Vec2 c = ellipses.centre(ellipse);
    nx[count] = normal.x(), ny[count] = normal.y(), h[count] = offset;
    u[count] = c.x(), v[count] = c.y(), xx[count] = S[0], xy[count] = S[1], yy[count] = S[2];
    ++count;
    return true;
  }
};

// Fills the supports (a given offset, a common tangent's, is already the larger of two
// ellipses' supports, so the maximum keeps it) and closes the cycle.
COVTRACK_VECTOR_CLONES
void close_with_supports(ShortcutLines& lines) {
  const std::size_t n = lines.count;
  for (std::size_t p = 0; p < n; ++p) {
    const double x = lines.nx[p], y = lines.ny[p];
    const double support = x * lines.u[p] + y * lines.v[p] + std::sqrt(std::max(x * x * lines.xx[p] + 2 * x * y * lines.xy[p] + y * y * lines.yy[p], 0.0));
    lines.h[p] = std::max(lines.h[p], support);
  }
  lines.nx[n] = lines.nx[0], lines.ny[n] = lines.ny[0], lines.h[n] = lines.h[0];
}

// Corner p of lines p and p + 1, and whether each lies within tol of the point of line
// p's ellipse facing it (the farthest along n_p + n_p+1), as in the search. (The squared
// distances go to an array checked after the loop: a running maximum would be a
// reduction, which does not vectorise. corner() and Ellipses::farthest_point are written
// out in scalars here: through Eigen's Vec2 the loop does not vectorise.)
COVTRACK_VECTOR_CLONES
bool corners_within(ShortcutLines& lines, double tol) {
  const std::size_t n = lines.count;
  for (std::size_t p = 0; p < n; ++p) {
    const double ax = lines.nx[p], ay = lines.ny[p], bx = lines.nx[p + 1], by = lines.ny[p + 1];
    const double inverse_det = 1 / (ax * by - ay * bx);
    const double cx = inverse_det * (lines.h[p] * by - lines.h[p + 1] * ay), cy = inverse_det * (lines.h[p + 1] * ax - lines.h[p] * bx);
    const double mx = ax + bx, my = ay + by;
    const double sx = lines.xx[p] * mx + lines.xy[p] * my, sy = lines.xy[p] * mx + lines.yy[p] * my;
    const double r2 = mx * sx + my * sy;
    const double inverse_r = r2 > 0 ? 1 / std::sqrt(r2) : 0.0;  // a point: its centre
    const double dx = cx - (lines.u[p] + sx * inverse_r), dy = cy - (lines.v[p] + sy * inverse_r);
    lines.gap2[p] = dx * dx + dy * dy;
    lines.qx[p] = cx, lines.qy[p] = cy;
  }
  for (std::size_t p = 0; p < n; ++p)
    if (!(lines.gap2[p] <= tol * tol)) return false;
  return true;
}

// How many times each arc's angle is halved (see expand_by_arcs): arc i runs from the
// normal of tangents[i] to that of the next, on tangents[i]'s ellipse. Blocks of arcs side
// by side, in loops of fixed length that vectorise: each count is a chain of square roots
// and divisions that would leave the processor waiting, arc after arc. False where an arc
// turns clockwise or by about pi, or needs more than `most` halvings (a sharp or
// degenerate ellipse).
bool arc_halvings(const Ellipses& ellipses, std::span<const ArcLine> tangents, double tol, int most,
                  std::vector<int>& halvings) {
  constexpr int kArcs = 8;  // per block; a short last block repeats its first arc
  constexpr double pi = std::numbers::pi, inf = std::numeric_limits<double>::infinity();
  const std::size_t k = tangents.size();
  halvings.resize(k);
  for (std::size_t first = 0; first < k; first += kArcs) {
    const int count = static_cast<int>(std::min<std::size_t>(kArcs, k - first));
    double sx[kArcs], sy[kArcs], ex[kArcs], ey[kArcs], xx[kArcs], xy[kArcs], yy[kArcs], ratio[kArcs];
    for (int j = 0; j < kArcs; ++j) {
      const std::size_t i = first + (j < count ? j : 0);
      const Vec2& start = tangents[i].normal;
      const Vec2& end = tangents[i + 1 == k ? 0 : i + 1].normal;
      const Vec3 S = ellipses.shape(tangents[i].ellipse);
      sx[j] = start.x(), sy[j] = start.y(), ex[j] = end.x(), ey[j] = end.y();
      xx[j] = S[0], xy[j] = S[1], yy[j] = S[2];
    }
    for (int j = 0; j < kArcs; ++j) {
      // An upper bound of the arc's angle, without trigonometry: theta = 2 atan(x),
      // x = cross / (1 + dot), and atan(x) is within 0.005 rad of x / (1 + 0.28125 x^2) for
      // |x| <= 1 (of pi/2 - x / (x^2 + 0.28125) beyond).
      const double cross = sx[j] * ey[j] - sy[j] * ex[j], dot = sx[j] * ex[j] + sy[j] * ey[j];
      const double x = cross / (1 + dot);
      const double half = x <= 1 ? x / (1 + 0.28125 * x * x) : pi / 2 - x / (x * x + 0.28125);
      const double angle2 = 4 * (half + 0.005) * (half + 0.005);
      // ratio = (angle / step)^2, with step the widest gap whose corner stays within tol of
      // a circle of the ellipse's largest radius of curvature rho = a^2 / b (semi-axes
      // a >= b): (step / 2)^2 = 2r / (1 + r), r = tol / rho, so ratio = angle^2 (rho + tol) /
      // (8 tol). A point (rho = 0) takes any gap below pi, a segment (rho infinite) none.
      const double mid = 0.5 * (xx[j] + yy[j]), d = 0.5 * (xx[j] - yy[j]);
      const double spread = std::sqrt(d * d + xy[j] * xy[j]);
      const double a2 = mid + spread, b2 = std::max(mid - spread, 0.0);
      const double rho = a2 / std::sqrt(b2);
      const bool turns = (cross > 1e-9) & (dot >= -0.99);
      const double arc_ratio = a2 > 0 ? angle2 * (rho + tol) / (8 * tol) : angle2 / (pi * pi);
      ratio[j] = turns ? arc_ratio : inf;
    }
    // The fewest halvings h with ratio <= 4^h.
    for (int j = 0; j < count; ++j) {
      int h = 0;
      double power = 1;  // 4^h
      for (; h <= most && !(ratio[j] <= power); ++h) power *= 4;
      if (h > most) return false;
      halvings[first + j] = h;
    }
  }
  return true;
}

// The shortcut. Usually the boundary of the ellipses' hull is an arc of each mean hull
// vertex's ellipse, joined to the next by their common outer tangent. This builds that
// directly: the tangents solved side by side (region_tangents.hpp); each arc's directions by
// halving its angle until the ellipse's largest radius of curvature rho gives a corner
// within the tolerance (the circle bound rho (1/cos(g/2) - 1) <= tol holds for
// g/2 <= sqrt(2r / (1 + r)), r = tol / rho). Nothing is assumed: every line is checked to be a
// support of the whole set and every corner to be within the tolerance of its ellipse's
// point facing it, as in the search. It returns false where any check fails (an ellipse off
// the mean hull sticking out, one swallowed by its neighbours, a sharp or degenerate arc):
// the caller then searches.
bool expand_by_arcs(Ellipses& ellipses, std::span<const ProjectedVertex> vertices,
                    std::span<const int> hull, double s2, const RegionOptions& o, Polygon& outer) {
  const std::size_t k = hull.size();
  if (k < 3) return false;
  constexpr int kMostHalvings = 6;  // 64 lines per arc
  const double tol = o.max_polygon_error_px;

  // The tangent of hull edge i (hull[i] -> hull[i + 1]) starts the arc of ellipse hull[i + 1].
  thread_local std::vector<TangentLine> solved;
  thread_local std::vector<ArcLine> tangents;
  hull_tangents(k, [&](std::size_t i) -> const ProjectedVertex& { return vertices[hull[i]]; }, s2,
                TangentSide::outer, solved);
  tangents.resize(k);
  for (std::size_t i = 0; i < k; ++i) {
    if (!solved[i].solved) return false;
    tangents[i] = {solved[i].normal, solved[i].offset, static_cast<std::size_t>(hull[(i + 1) % k])};
  }

  thread_local std::vector<int> halvings;
  if (!arc_halvings(ellipses, tangents, tol, kMostHalvings, halvings)) return false;
  thread_local ShortcutLines lines;
  lines.count = 0;
  constexpr double kUnknown = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < k; ++i) {
    const ArcLine& start = tangents[i];
    const Vec2& end = tangents[(i + 1) % k].normal;
    if (!lines.push(ellipses, start.normal, start.offset, start.ellipse)) return false;
    // Directions by halving: normalised sums of neighbours, uniform in angle.
    const int n = 1 << halvings[i];
    Vec2 dirs[(1 << kMostHalvings) + 1];
    dirs[0] = start.normal, dirs[n] = end;
    for (int gap = n; gap > 1; gap /= 2)
      for (int j = gap / 2; j < n; j += gap) dirs[j] = (dirs[j - gap / 2] + dirs[j + gap / 2]).normalized();
    for (int j = 1; j < n; ++j)
      if (!lines.push(ellipses, dirs[j], kUnknown, start.ellipse)) return false;
    if (static_cast<int>(lines.size()) > o.max_outer_corners) return false;
  }
  close_with_supports(lines);
  // Every line a support of the whole set (to rounding), every corner within the tolerance
  // of its arc's ellipse.
  const std::span<const double> nx(lines.nx, lines.size()), ny(lines.ny, lines.size()), h(lines.h, lines.size());
  if (!ellipses.hold_all(nx, ny, h)) return false;
  if (!corners_within(lines, tol)) return false;
  outer.clear();
  for (std::size_t p = 0; p < lines.size(); ++p) {
    const Vec2 q(lines.qx[p], lines.qy[p]);
    if (outer.empty() || (q - outer.back()).squaredNorm() > 1e-18) outer.push_back(q);
  }
  while (outer.size() > 1 && (outer.front() - outer.back()).squaredNorm() <= 1e-18) outer.pop_back();
  return true;
}

}  // namespace

// One clone per instruction set (vector_clones.hpp); flatten inlines the helpers, so the
// supports' loop is compiled for the clone's instructions too.
[[gnu::flatten]] COVTRACK_VECTOR_CLONES
void expand_region(std::span<const ProjectedVertex> vertices, std::span<const int> mean_hull,
                   const RegionOptions& o, Polygon& outer) {
  outer.clear();
  if (vertices.empty()) return;
  const double s2 = std::pow(confidence_scale(o.confidence), 2);
  thread_local Ellipses ellipses;
  ellipses.assign(vertices, s2);
  if (o.outer_by_arcs && expand_by_arcs(ellipses, vertices, mean_hull, s2, o, outer)) return;
  outer.clear();  // the shortcut may have left corners behind
  const double tolerance2 = o.max_polygon_error_px * o.max_polygon_error_px;

  // Start with 8 directions; split a gap while the corner of its two lines lies farther
  // than the tolerance from the points of the set it is compared with (below). Depth-first
  // with an explicit stack: corners come out in counter-clockwise order, the last line
  // being the first one again.
  constexpr double kSmallestGap = 1e-7;  // sin of the gap; below it a corner is as tight as doubles get
  constexpr double h = std::numbers::sqrt2 / 2;
  static const Vec2 kInitial[] = {{1, 0}, {h, h}, {0, 1}, {-h, h}, {-1, 0}, {-h, -h}, {0, -1}, {h, -h}};
  const SupportLine first = ellipses.support(kInitial[0]);
  thread_local std::vector<SupportLine> pending;  // lines still to visit, the next one at the back
  pending.clear();
  pending.push_back(first);
  for (int k = 7; k >= 1; --k) pending.push_back(ellipses.support(kInitial[k]));
  SupportLine current = first;
  while (!pending.empty()) {
    const SupportLine& next = pending.back();
    const Vec2 q = corner(current.normal, current.offset, next.normal, next.offset);
    // The corner's distance to the hull is at most its distance to any point of the hull:
    // the chord between the contacts, and, when one ellipse touches both lines, that
    // ellipse's point facing the corner (the bisector's contact). On a circle of radius R
    // and a gap g the chord gives R (1/cos(g/2) - cos(g/2)), the arc R (1/cos(g/2) - 1),
    // about half: fewer splits along the ellipses for the same guarantee.
    double gap2 = squared_distance_to_segment(q, current.contact, next.contact);
    if (gap2 > tolerance2 && current.ellipse == next.ellipse)
      gap2 = std::min(gap2, (q - ellipses.farthest_point(current.ellipse,
                                                         current.normal + next.normal))
                                .squaredNorm());
    const bool loose = gap2 > tolerance2;
    if (loose && cross(current.normal, next.normal) > kSmallestGap &&
        static_cast<int>(outer.size() + pending.size()) < o.max_outer_corners) {
      pending.push_back(ellipses.support(split_direction(current, next)));
      continue;
    }
    if (outer.empty() || (q - outer.back()).squaredNorm() > 1e-18) outer.push_back(q);
    current = next;
    pending.pop_back();
  }
  // The last corner (between the lines at 2 pi and 0) repeats the first when they meet.
  while (outer.size() > 1 && (outer.front() - outer.back()).squaredNorm() <= 1e-18) outer.pop_back();
}

void expand_region(std::span<const ProjectedVertex> vertices, const RegionOptions& o,
                   Polygon& outer) {
  thread_local std::vector<Vec2> means;
  thread_local std::vector<int> hull;
  means.clear();
  for (const ProjectedVertex& v : vertices) means.push_back(v.mean_px);
  convex_hull_indices(means, hull);
  expand_region(vertices, hull, o, outer);
}

Polygon expand_region(std::span<const ProjectedVertex> vertices, const RegionOptions& o) {
  Polygon outer;
  expand_region(vertices, o, outer);
  return outer;
}

}  // namespace covtrack::client
