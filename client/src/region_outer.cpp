// The outer region as the polygon of support lines of the hull of the confidence
// ellipses, refined where it is loose (see regions.hpp for the guarantee).
#include <cmath>
#include <numbers>

#include "covtrack/client/regions.hpp"

namespace covtrack::client {
namespace {

// A support line of the set: normal . x <= offset, touching it at `contact`.
struct SupportLine {
  Vec2 normal;  // unit
  double offset;
  Vec2 contact;
};

struct ScaledEllipse {
  Vec2 center;
  double sxx, sxy, syy;  // shape = scale^2 * covariance
};

SupportLine support(std::span<const ScaledEllipse> ellipses, const Vec2& n) {
  SupportLine best{n, -std::numeric_limits<double>::infinity(), Vec2::Zero()};
  for (const ScaledEllipse& e : ellipses) {
    // max over the ellipse of n . x = n . c + sqrt(n^T S n), reached at c + S n / sqrt(.).
    const Vec2 Sn(e.sxx * n.x() + e.sxy * n.y(), e.sxy * n.x() + e.syy * n.y());
    const double r = std::sqrt(std::max(n.dot(Sn), 0.0));
    const double h = n.dot(e.center) + r;
    if (h > best.offset) {
      best.offset = h;
      best.contact = r > 0 ? Vec2(e.center + Sn / r) : e.center;
    }
  }
  return best;
}

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Where two support lines (normals less than pi apart) cross.
Vec2 corner(const SupportLine& a, const SupportLine& b) {
  const double det = cross(a.normal, b.normal);
  return Vec2(a.offset * b.normal.y() - b.offset * a.normal.y(),
              b.offset * a.normal.x() - a.offset * b.normal.x()) / det;
}

// The direction to split the gap between lines a and b: the normal of the chord between
// their contact points. When the contacts are on two different ellipses it converges to
// their common tangent at once (exactly, for points), where bisecting would only creep up
// on it. Bisects when the chord is degenerate or its normal is not inside the gap.
// Directions are unit vectors throughout: no trigonometry per split.
Vec2 split_direction(const SupportLine& a, const SupportLine& b) {
  const Vec2 bisector = (a.normal + b.normal).normalized();
  const Vec2 chord = b.contact - a.contact;
  if (chord.squaredNorm() == 0) return bisector;
  const Vec2 outward = Vec2(chord.y(), -chord.x()).normalized();  // chord turned by -90 deg
  const double margin = 1e-3 * cross(a.normal, b.normal);
  return cross(a.normal, outward) > margin && cross(outward, b.normal) > margin ? outward : bisector;
}

double distance_to_segment(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (q - (a + t * ab)).norm();
}

}  // namespace

Polygon expand_region(std::span<const ProjectedVertex> vertices, const RegionOptions& o) {
  if (vertices.empty()) return {};
  const double s2 = std::pow(confidence_scale(o.confidence), 2);
  std::vector<ScaledEllipse> ellipses;
  ellipses.reserve(vertices.size());
  for (const ProjectedVertex& v : vertices) {
    const Mat2& C = v.covariance_px2;
    ellipses.push_back({v.mean_px, s2 * C(0, 0), s2 * 0.5 * (C(0, 1) + C(1, 0)), s2 * C(1, 1)});
  }

  // Start with 8 directions; split a gap while the corner of its two lines lies farther
  // than the tolerance from the segment between their contact points (a chord of the
  // convex set, so inside it). Depth-first with an explicit stack: corners come out in
  // counter-clockwise order, the last line being the first one again.
  constexpr double kSmallestGap = 1e-7;  // sin of the gap; below it a corner is as tight as doubles get
  constexpr double h = std::numbers::sqrt2 / 2;
  static const Vec2 kInitial[] = {{1, 0}, {h, h}, {0, 1}, {-h, h}, {-1, 0}, {-h, -h}, {0, -1}, {h, -h}};
  const SupportLine first = support(ellipses, kInitial[0]);
  Polygon outer;
  outer.reserve(32);
  std::vector<SupportLine> pending;  // lines still to visit, the next one at the back
  pending.reserve(64);
  pending.push_back(first);
  for (int k = 7; k >= 1; --k) pending.push_back(support(ellipses, kInitial[k]));
  SupportLine current = first;
  while (!pending.empty()) {
    const SupportLine& next = pending.back();
    const Vec2 q = corner(current, next);
    const bool loose = distance_to_segment(q, current.contact, next.contact) > o.max_polygon_error_px;
    if (loose && cross(current.normal, next.normal) > kSmallestGap &&
        static_cast<int>(outer.size() + pending.size()) < o.max_outer_corners) {
      pending.push_back(support(ellipses, split_direction(current, next)));
      continue;
    }
    if (outer.empty() || (q - outer.back()).squaredNorm() > 1e-18) outer.push_back(q);
    current = next;
    pending.pop_back();
  }
  // The last corner (between the lines at 2 pi and 0) repeats the first when they meet.
  while (outer.size() > 1 && (outer.front() - outer.back()).squaredNorm() <= 1e-18) outer.pop_back();
  return outer;
}

}  // namespace covtrack::client
