// The outer region as the polygon of support lines of the hull of the confidence
// ellipses: built from the mean hull's tangents and arcs where every check passes, else
// searched for and refined where it is loose (see regions.hpp for the guarantee).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include "angle_bound.hpp"
#include "covtrack/client/regions.hpp"
#include "regions_from_tangents.hpp"
#include "vector_clones.hpp"

namespace covtrack::client {
namespace {

// A line n . x <= offset holds a support up to this (rounding in the lines' own solves).
double with_slack(double offset) { return offset + 1e-9 * (1 + std::abs(offset)); }

// Normals turning by less than this (counter-clockwise) leave no arc between them.
constexpr double kLeastTurn = 1e-9;

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
  static constexpr std::size_t kBlock = 8;       // of ellipses
  static constexpr std::size_t kLinesBlock = 4;  // of lines in hold_all (see there)

  void assign(std::span<const ProjectedVertex> vertices, double scale2) {
    const std::size_t n = vertices.size();
    const std::size_t padded = (n + kBlock - 1) / kBlock * kBlock;
    for (auto* column : {&cu_, &cv_, &sxx_, &sxy_, &syy_, &h_}) column->resize(padded);
    for (std::size_t i = 0; i < padded; ++i) {
      const ProjectedVertex& v = vertices[i < n ? i : 0];
      const Vec3 S = confidence_shape(v.covariance_px2, scale2);
      cu_[i] = v.mean_px.x(), cv_[i] = v.mean_px.y();
      sxx_[i] = S[0], sxy_[i] = S[1], syy_[i] = S[2];
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

  // Whether every line n_j . x <= h_j holds every ellipse (to rounding); the lines' count a
  // multiple of kLinesBlock. A block of lines at a time, one ellipse after another, so that
  // the block's worst excess stays in registers (a maximum over the ellipses would be a
  // reduction, which does not vectorise). Blocks of 4: of 8 the plain clone ran out of
  // registers (4% slower a frame), and with AVX-512 4 were as fast. No square roots: with
  // the room r = h + slack - n . c left beyond the centre, the support n . c + sqrt(n'Sn)
  // fits iff r >= 0 and n'Sn <= r^2. The block's lines are vectors of 4 (one register)
  // with AVX2; without it, two vectors of 2: GCC splits comparisons of vectors wider than
  // the registers into scalars (vector_clones.hpp). As plain loops over the block, GCC 12
  // left the AVX2 clone scalar (8% of the first-order frame, measured).
  bool hold_all(std::span<const double> nx, std::span<const double> ny, std::span<const double> h) {
    return vector_clones_have_avx2() ? hold_all_in<DoubleLanes4>(nx, ny, h) : hold_all_in<DoubleLanes2>(nx, ny, h);
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
  template <class Lanes>
  bool hold_all_in(std::span<const double> nx, std::span<const double> ny, std::span<const double> h) {
    constexpr std::size_t kLanes = sizeof(Lanes) / sizeof(double);
    constexpr std::size_t kGroups = kLinesBlock / kLanes;
    const Lanes zero = {}, one = zero + 1;
    for (std::size_t first = 0; first < h.size(); first += kLinesBlock) {
      Lanes x[kGroups], y[kGroups], limit[kGroups], worst[kGroups];
      for (std::size_t j = 0; j < kLinesBlock; ++j)
        x[j / kLanes][j % kLanes] = nx[first + j], y[j / kLanes][j % kLanes] = ny[first + j],
        limit[j / kLanes][j % kLanes] = with_slack(h[first + j]);
      for (auto& w : worst) w = zero - std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < cu_.size(); ++i)
        for (std::size_t g = 0; g < kGroups; ++g) {
          const Lanes room = limit[g] - (x[g] * cu_[i] + y[g] * cv_[i]);
          const Lanes spread2 = x[g] * x[g] * sxx_[i] + 2 * x[g] * y[g] * sxy_[i] + y[g] * y[g] * syy_[i];
          const Lanes excess = room < zero ? one : spread2 - room * room;
          worst[g] = worst[g] < excess ? excess : worst[g];
        }
      for (const Lanes& w : worst)
        for (std::size_t j = 0; j < kLanes; ++j)
          if (w[j] > 0) return false;
    }
    return true;
  }

  std::vector<double> cu_, cv_, sxx_, sxy_, syy_, h_;
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

// How an arc is split: how many times its angle is halved, and its directions after one
// halving (middle) and two (quarter, three quarters).
struct ArcPlan {
  int halvings;
  Vec2 middle, quarter, three_quarters;
};

// The shortcut's lines as structure-of-arrays, each with the ellipse of its arc (centre u,
// v; shape xx, xy, yy): their supports and their corners' checks are loops over all lines
// that vectorise, where line after line would wait on a square root and two divisions each.
// Fixed arrays, so the compiler sees that they do not overlap; an object needing more lines
// goes to the search. Lines size() to padded() repeat line 0, so that the loops run over
// whole vectors and corner p (of lines p and p + 1) needs no wrap-around.
struct ShortcutLines {
  static constexpr std::size_t kMost = 64;  // a multiple of kVector
  static constexpr std::size_t kVector = 8;
  double nx[kMost + 1], ny[kMost + 1], h[kMost + 1], u[kMost], v[kMost], xx[kMost], xy[kMost],
      yy[kMost], qx[kMost], qy[kMost], gap2[kMost];
  std::size_t count = 0;

  std::size_t size() const { return count; }
  std::size_t padded() const { return (count + kVector - 1) / kVector * kVector; }
  // The arc of `ellipse` from `start` (a common tangent: normal, offset) towards the normal
  // `end` in 2^h directions (h = plan.halvings), uniform in angle: lines count .. count +
  // 2^h - 1. The offsets of all but the first are -infinity: supports of their own ellipse,
  // filled in by close_with_supports. Up to two halvings take their directions from the
  // plan (block_halvings). False when full.
  bool add_arc(const Ellipses& ellipses, const ArcLine& start, const Vec2& end, const ArcPlan& plan) {
    const int halvings = plan.halvings;
    const std::size_t n = std::size_t{1} << halvings, p = count;
    if (p + n > kMost) return false;
    double *x = nx + p, *y = ny + p;
    if (halvings <= 2) {
      x[0] = start.normal.x(), y[0] = start.normal.y();
      if (halvings == 1) x[1] = plan.middle.x(), y[1] = plan.middle.y();
      if (halvings == 2) {
        x[1] = plan.quarter.x(), y[1] = plan.quarter.y(), x[2] = plan.middle.x(), y[2] = plan.middle.y();
        x[3] = plan.three_quarters.x(), y[3] = plan.three_quarters.y();
      }
      return fill_arc(ellipses, start, n);
    }
    // By halving: each direction the normalised sum of its neighbours on the level above.
    // The sums of one level all span the same angle, so one length serves for them all. (End
    // goes to line p + n, the next arc's start, or for the last arc the spare entry: both
    // are written again.)
    x[0] = start.normal.x(), y[0] = start.normal.y(), x[n] = end.x(), y[n] = end.y();
    for (std::size_t gap = n; gap > 1; gap /= 2) {
      const std::size_t half = gap / 2;
      const double sx = x[0] + x[gap], sy = y[0] + y[gap], inverse_length = 1 / std::sqrt(sx * sx + sy * sy);
      for (std::size_t j = half; j < n; j += gap)
        x[j] = (x[j - half] + x[j + half]) * inverse_length, y[j] = (y[j - half] + y[j + half]) * inverse_length;
    }
    return fill_arc(ellipses, start, n);
  }

 private:
  // The rest of the arc's n lines after their normals: its ellipse, and the start's offset.
  bool fill_arc(const Ellipses& ellipses, const ArcLine& start, std::size_t n) {
    const std::size_t p = count;
    const Vec3 S = ellipses.shape(start.ellipse);
    const Vec2 c = ellipses.centre(start.ellipse);
    for (std::size_t j = p; j < p + n; ++j)
      h[j] = -std::numeric_limits<double>::infinity(), u[j] = c.x(), v[j] = c.y(), xx[j] = S[0], xy[j] = S[1], yy[j] = S[2];
    h[p] = start.offset;
    count = p + n;
    return true;
  }
};

// Fills the supports (a given offset, a common tangent's, is already the larger of two
// ellipses' supports, so the maximum keeps it), closes the cycle and pads.
COVTRACK_VECTOR_CLONES
void close_with_supports(ShortcutLines& lines) {
  const std::size_t n = lines.padded();
  for (std::size_t p = lines.count; p <= n; ++p) {
    lines.nx[p] = lines.nx[0], lines.ny[p] = lines.ny[0], lines.h[p] = lines.h[0];
    if (p < n) lines.u[p] = lines.u[0], lines.v[p] = lines.v[0], lines.xx[p] = lines.xx[0], lines.xy[p] = lines.xy[0], lines.yy[p] = lines.yy[0];
  }
  for (std::size_t p = 0; p < n; ++p) {
    const double x = lines.nx[p], y = lines.ny[p];
    const double support = x * lines.u[p] + y * lines.v[p] + std::sqrt(std::max(x * x * lines.xx[p] + 2 * x * y * lines.xy[p] + y * y * lines.yy[p], 0.0));
    lines.h[p] = std::max(lines.h[p], support);
  }
  lines.h[n] = lines.h[0];
}

// Corner p of lines p and p + 1, and whether each lies within tol of the point of line
// p's ellipse facing it (the farthest along n_p + n_p+1), as in the search. (The squared
// distances go to an array checked after the loop: a running maximum would be a
// reduction, which does not vectorise. corner() and Ellipses::farthest_point are written
// out in scalars here: through Eigen's Vec2 the loop does not vectorise.)
COVTRACK_VECTOR_CLONES
bool corners_within(ShortcutLines& lines, double tol) {
  // The padding's corners (of equal lines) are computed, and not checked.
  const std::size_t n = lines.padded();
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
  for (std::size_t p = 0; p < lines.count; ++p)
    if (!(lines.gap2[p] <= tol * tol)) return false;
  return true;
}

// A block of arcs side by side (see arc_halvings): start and end normals, the shape of the
// ellipse (xx, xy, yy); out, the count of halvings found and the directions of the first two
// (ArcPlan).
constexpr int kArcs = 8;
struct ArcBlock {
  double sx[kArcs], sy[kArcs], ex[kArcs], ey[kArcs], xx[kArcs], xy[kArcs], yy[kArcs];
  std::int64_t halvings[kArcs];
  double mx[kArcs], my[kArcs], q1x[kArcs], q1y[kArcs], q3x[kArcs], q3y[kArcs];
};

// Each arc's count of halvings in loops of fixed length without branches, which vectorise
// (vector_clones.hpp): each count is a chain of square roots and divisions that would leave
// the processor waiting, arc after arc. Very large where an arc turns clockwise or by about
// pi, or is on a segment (a degenerate ellipse).
COVTRACK_VECTOR_CLONES
void block_halvings(ArcBlock& arcs, double tol) {
  constexpr double pi = std::numbers::pi, inf = std::numeric_limits<double>::infinity();
  for (int j = 0; j < kArcs; ++j) {
    // An upper bound of the arc's angle, within 2e-5 rad (meaningless where the arc does
    // not turn: such an arc is refused below).
    const double cross = arcs.sx[j] * arcs.ey[j] - arcs.sy[j] * arcs.ex[j];
    const double dot = arcs.sx[j] * arcs.ex[j] + arcs.sy[j] * arcs.ey[j];
    const double angle = angle_at_most(cross, dot), angle2 = angle * angle;
    // ratio = (angle / step)^2, with step the widest gap whose corner stays within tol of
    // a circle of the ellipse's largest radius of curvature rho = a^2 / b (semi-axes
    // a >= b): (step / 2)^2 = 2r / (1 + r), r = tol / rho, so ratio = angle^2 (rho + tol) /
    // (8 tol). A point (rho = 0) takes any gap below pi, a segment (rho infinite) none.
    const double mid = 0.5 * (arcs.xx[j] + arcs.yy[j]), d = 0.5 * (arcs.xx[j] - arcs.yy[j]);
    const double spread = std::sqrt(d * d + arcs.xy[j] * arcs.xy[j]);
    const double a2 = mid + spread, b2 = std::max(mid - spread, 0.0);
    const double rho = a2 / std::sqrt(b2);
    const bool turns = (cross > kLeastTurn) & (dot >= -0.99);
    const double arc_ratio = a2 > 0 ? angle2 * (rho + tol) / (8 * tol) : angle2 / (pi * pi);
    const double ratio = turns ? arc_ratio : inf;
    // The fewest halvings h with ratio <= 4^h, that is 2h >= ceil(log2(ratio)), read off
    // the bits of the (non-negative) double: its exponent, plus one unless the mantissa is
    // zero. Infinity and NaN give about 512, zero and subnormals none.
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(ratio);
    const std::int64_t exponent = static_cast<std::int64_t>(bits >> 52) - 1023;
    const std::int64_t ceil_log2 = exponent + ((bits & 0xFFFFFFFFFFFFFull) != 0 ? 1 : 0);
    arcs.halvings[j] = std::max<std::int64_t>((ceil_log2 + 1) >> 1, 0);
    // The first two halvings' directions, as ShortcutLines::add_arc would halve them (the
    // same operations, so the same bits), here side by side for 99% of the arcs (2^h lines,
    // h <= 2), where one arc at a time each level waited on a square root and a division.
    // (NaN where the arc turns by pi: such an arc is refused above.)
    const double first = 1 / std::sqrt((arcs.sx[j] + arcs.ex[j]) * (arcs.sx[j] + arcs.ex[j]) +
                                       (arcs.sy[j] + arcs.ey[j]) * (arcs.sy[j] + arcs.ey[j]));
    const double mx = (arcs.sx[j] + arcs.ex[j]) * first, my = (arcs.sy[j] + arcs.ey[j]) * first;
    const double second = 1 / std::sqrt((arcs.sx[j] + mx) * (arcs.sx[j] + mx) + (arcs.sy[j] + my) * (arcs.sy[j] + my));
    arcs.mx[j] = mx, arcs.my[j] = my;
    arcs.q1x[j] = (arcs.sx[j] + mx) * second, arcs.q1y[j] = (arcs.sy[j] + my) * second;
    arcs.q3x[j] = (mx + arcs.ex[j]) * second, arcs.q3y[j] = (my + arcs.ey[j]) * second;
  }
}

// How each arc is split (see expand_by_arcs): arc i runs from the normal of tangents[i] to
// that of the next, on tangents[i]'s ellipse. False where an arc turns clockwise or by
// about pi, or needs more than `most` halvings (a sharp or degenerate ellipse).
bool plan_arcs(const Ellipses& ellipses, std::span<const ArcLine> tangents, double tol, int most,
               std::vector<ArcPlan>& plans) {
  const std::size_t k = tangents.size();
  plans.resize(k);
  ArcBlock arcs;
  for (std::size_t first = 0; first < k; first += kArcs) {
    const int count = static_cast<int>(std::min<std::size_t>(kArcs, k - first));
    for (int j = 0; j < kArcs; ++j) {  // a short last block repeats its first arc
      const std::size_t i = first + (j < count ? j : 0);
      const Vec2& start = tangents[i].normal;
      const Vec2& end = tangents[i + 1 == k ? 0 : i + 1].normal;
      const Vec3 S = ellipses.shape(tangents[i].ellipse);
      arcs.sx[j] = start.x(), arcs.sy[j] = start.y(), arcs.ex[j] = end.x(), arcs.ey[j] = end.y();
      arcs.xx[j] = S[0], arcs.xy[j] = S[1], arcs.yy[j] = S[2];
    }
    block_halvings(arcs, tol);
    for (int j = 0; j < count; ++j) {
      if (arcs.halvings[j] > most) return false;
      plans[first + j] = {static_cast<int>(arcs.halvings[j]), Vec2(arcs.mx[j], arcs.my[j]),
                          Vec2(arcs.q1x[j], arcs.q1y[j]), Vec2(arcs.q3x[j], arcs.q3y[j])};
    }
  }
  return true;
}

// Whether the arc from tangent a to tangent b turns counter-clockwise (see refine_hull).
bool arc_turns(const TangentLine& a, const TangentLine& b) { return cross(a.normal, b.normal) > kLeastTurn; }

// Whether every arc between consecutive tangents does.
bool arcs_turn(std::span<const TangentLine> tangents) {
  for (std::size_t i = 0; i < tangents.size(); ++i)
    if (!arc_turns(tangents[i], tangents[i + 1 == tangents.size() ? 0 : i + 1])) return false;
  return true;
}

// The hull of the ellipses can differ from the mean hull in two ways, both mended here
// before its tangents are solved anew (for a few rounds; whether the result holds every
// ellipse is checked later, as for any hull):
//  - an ellipse of a vertex inside the mean hull sticks out of an edge's tangent: it goes
//    into the hull there (the one sticking out most, per edge);
//  - the ellipse of a hull vertex is swallowed by its neighbours': the tangent to the
//    previous vertex turns past the one to the next (the arc between them would turn
//    clockwise), so it has no arc on the boundary: it leaves the hull.
// False where fewer than 3 vertices are left or the rounds run out.
bool refine_hull(const Ellipses& ellipses, std::span<const ProjectedVertex> vertices, double s2,
                 std::vector<int>& hull, std::vector<TangentLine>& solved) {
  thread_local std::vector<int> next;
  thread_local std::vector<std::pair<double, int>> worst;  // per edge: excess, ellipse
  for (int round = 0; round < 4; ++round) {
    const std::size_t k = hull.size();
    worst.assign(k, {0.0, -1});
    for (std::size_t e = 0; e < vertices.size(); ++e) {
      if (std::find(hull.begin(), hull.end(), static_cast<int>(e)) != hull.end()) continue;
      for (std::size_t i = 0; i < k; ++i) {
        const Vec2& n = solved[i].normal;
        const Vec2 far = ellipses.farthest_point(e, n);
        const double excess = n.dot(far) - with_slack(solved[i].offset);
        if (excess > worst[i].first) worst[i] = {excess, static_cast<int>(e)};
      }
    }
    next.clear();
    for (std::size_t i = 0; i < k; ++i) {
      const std::size_t after = i + 1 == k ? 0 : i + 1;  // the arc of vertex `after`
      if (arc_turns(solved[i], solved[after])) next.push_back(hull[after]);
      if (worst[after].second >= 0) next.push_back(worst[after].second);  // in edge after -> after + 1
    }
    if (next.size() < 3) return false;
    // Unchanged, `next` is the hull from its second vertex round to its first.
    const bool changed = next.size() != k || !std::equal(next.begin(), next.end() - 1, hull.begin() + 1) || next.back() != hull.front();
    if (!changed) return true;
    hull.swap(next);
    hull_tangents(hull.size(), [&](std::size_t i) -> const ProjectedVertex& { return vertices[hull[i]]; }, s2,
                  nullptr, &solved);
  }
  return false;
}

// The shortcut's polygon from the tangents of a hull of the ellipses (hull[i] -> hull[i + 1]
// starts the arc of ellipse hull[i + 1]): see expand_by_arcs.
enum class ArcsResult { built, sticks_out, failed };
ArcsResult arcs_polygon(Ellipses& ellipses, std::span<const int> hull, std::span<const TangentLine> solved,
                        const RegionOptions& o, Polygon& outer) {
  const std::size_t k = hull.size();
  constexpr int kMostHalvings = 6;  // 64 lines per arc
  const double tol = o.max_polygon_error_px;
  thread_local std::vector<ArcLine> tangents;
  tangents.resize(k);
  for (std::size_t i = 0; i < k; ++i) {
    if (!solved[i].solved) return ArcsResult::failed;
    tangents[i] = {solved[i].normal, solved[i].offset, static_cast<std::size_t>(hull[(i + 1) % k])};
  }
  thread_local std::vector<ArcPlan> plans;
  if (!plan_arcs(ellipses, tangents, tol, kMostHalvings, plans)) return ArcsResult::failed;
  thread_local ShortcutLines lines;
  lines.count = 0;
  for (std::size_t i = 0; i < k; ++i)
    if (!lines.add_arc(ellipses, tangents[i], tangents[i + 1 == k ? 0 : i + 1].normal, plans[i])) return ArcsResult::failed;
  if (static_cast<int>(lines.size()) > o.max_outer_corners) return ArcsResult::failed;
  close_with_supports(lines);
  // Every line a support of the whole set (to rounding), every corner within the tolerance
  // of its arc's ellipse.
  const std::size_t padded = lines.padded();
  const std::span<const double> nx(lines.nx, padded), ny(lines.ny, padded), h(lines.h, padded);
  static_assert(ShortcutLines::kVector % Ellipses::kLinesBlock == 0, "hold_all takes whole blocks of lines");
  if (!ellipses.hold_all(nx, ny, h)) return ArcsResult::sticks_out;
  if (!corners_within(lines, tol)) return ArcsResult::failed;
  outer.clear();
  for (std::size_t p = 0; p < lines.size(); ++p) {
    const Vec2 q(lines.qx[p], lines.qy[p]);
    if (outer.empty() || (q - outer.back()).squaredNorm() > 1e-18) outer.push_back(q);
  }
  while (outer.size() > 1 && (outer.front() - outer.back()).squaredNorm() <= 1e-18) outer.pop_back();
  return ArcsResult::built;
}

// The shortcut. Usually the boundary of the ellipses' hull is an arc of each mean hull
// vertex's ellipse, joined to the next by their common outer tangent. This builds that
// directly: the tangents solved side by side (region_tangents.hpp); each arc's directions by
// halving its angle until the ellipse's largest radius of curvature rho gives a corner
// within the tolerance (the circle bound rho (1/cos(g/2) - 1) <= tol holds for
// g/2 <= sqrt(2r / (1 + r)), r = tol / rho). Nothing is assumed: every line is checked to be a
// support of the whole set and every corner to be within the tolerance of its ellipse's
// point facing it, as in the search. Where the ellipses' hull is not the mean hull's it is
// mended (refine_hull) and tried again. It returns false where any check still fails (a
// sharp or degenerate arc, say): the caller then searches.
bool expand_by_arcs(Ellipses& ellipses, std::span<const ProjectedVertex> vertices, double s2,
                    std::span<const int> mean_hull, std::span<const TangentLine> mean_solved,
                    const RegionOptions& o, Polygon& outer) {
  if (mean_hull.size() < 3 || mean_solved.size() != mean_hull.size()) return false;
  if (arcs_turn(mean_solved)) {
    const ArcsResult first = arcs_polygon(ellipses, mean_hull, mean_solved, o, outer);
    if (first != ArcsResult::sticks_out) return first == ArcsResult::built;
  }
  thread_local std::vector<int> hull;
  thread_local std::vector<TangentLine> solved;
  hull.assign(mean_hull.begin(), mean_hull.end());
  solved.assign(mean_solved.begin(), mean_solved.end());
  return refine_hull(ellipses, vertices, s2, hull, solved) &&
         arcs_polygon(ellipses, hull, solved, o, outer) == ArcsResult::built;
}

}  // namespace

// One clone per instruction set (vector_clones.hpp); flatten inlines the helpers, so the
// supports' loop is compiled for the clone's instructions too.
[[gnu::flatten]] COVTRACK_VECTOR_CLONES
void expand_region(std::span<const ProjectedVertex> vertices, std::span<const int> mean_hull,
                   std::span<const TangentLine> outer_lines, double s2, const RegionOptions& o,
                   Polygon& outer) {
  outer.clear();
  if (vertices.empty()) return;
  thread_local Ellipses ellipses;
  ellipses.assign(vertices, s2);
  if (o.outer_by_arcs && expand_by_arcs(ellipses, vertices, s2, mean_hull, outer_lines, o, outer)) return;
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
  // Each split adds a line and, in the end, a corner, so the corners' cap bounds the splits
  // too, except where corners coincide or are not numbers (supports that overflowed): the
  // splits are bounded as well, or such a set would be split down to kSmallestGap.
  int splits = 0;
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
        static_cast<int>(outer.size() + pending.size()) < o.max_outer_corners && splits < 2 * o.max_outer_corners) {
      ++splits;
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

void expand_region(std::span<const ProjectedVertex> vertices, std::span<const int> mean_hull,
                   const RegionOptions& o, Polygon& outer) {
  // The shortcut starts from the outer lines of the mean hull's edges (region_tangents.hpp).
  thread_local std::vector<TangentLine> lines;
  lines.clear();  // stays empty without the shortcut
  const double s2 = std::pow(confidence_scale(o.confidence), 2);
  if (o.outer_by_arcs)
    hull_tangents(mean_hull.size(), [&](std::size_t i) -> const ProjectedVertex& { return vertices[mean_hull[i]]; },
                  s2, nullptr, &lines);
  expand_region(vertices, mean_hull, lines, s2, o, outer);
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
