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
  Eigen::Index ellipse;  // the one touching
};

// The confidence ellipses, one column per quantity (centre u, v; shape = scale^2 times
// the covariance: xx, xy, yy), plus one column for the supports of the direction being
// evaluated: Eigen evaluates a direction's supports packet by packet (two or four
// ellipses per instruction, square roots included) without a temporary.
class Ellipses {
 public:
  Ellipses(std::span<const ProjectedVertex> vertices, double scale2) : e_(vertices.size(), 6) {
    for (Eigen::Index i = 0; i < e_.rows(); ++i) {
      const Mat2& C = vertices[i].covariance_px2;
      e_.row(i) << vertices[i].mean_px.x(), vertices[i].mean_px.y(), scale2 * C(0, 0),
          scale2 * 0.5 * (C(0, 1) + C(1, 0)), scale2 * C(1, 1), 0.0;
    }
  }

  SupportLine support(const Vec2& n) {
    // max over ellipse i of n . x = n . c_i + sqrt(n^T S_i n).
    const double x = n.x(), y = n.y();
    e_.col(5) = x * e_.col(0) + y * e_.col(1) +
                (x * x * e_.col(2) + 2 * x * y * e_.col(3) + y * y * e_.col(4)).max(0.0).sqrt();
    Eigen::Index best;
    const double offset = e_.col(5).maxCoeff(&best);
    return {n, offset, farthest_point(best, n), best};
  }

  // The point of ellipse i farthest along n (any length): c + S n / sqrt(n^T S n).
  Vec2 farthest_point(Eigen::Index i, const Vec2& n) const {
    const Vec2 c(e_(i, 0), e_(i, 1));
    const Vec2 Sn(e_(i, 2) * n.x() + e_(i, 3) * n.y(), e_(i, 3) * n.x() + e_(i, 4) * n.y());
    const double r = std::sqrt(std::max(n.dot(Sn), 0.0));
    return r > 0 ? Vec2(c + Sn / r) : c;
  }

 private:
  Eigen::ArrayXXd e_;
};

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

double squared_distance_to_segment(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (q - (a + t * ab)).squaredNorm();
}

}  // namespace

Polygon expand_region(std::span<const ProjectedVertex> vertices, const RegionOptions& o) {
  if (vertices.empty()) return {};
  const double s2 = std::pow(confidence_scale(o.confidence), 2);
  Ellipses ellipses(vertices, s2);
  const double tolerance2 = o.max_polygon_error_px * o.max_polygon_error_px;

  // Start with 8 directions; split a gap while the corner of its two lines lies farther
  // than the tolerance from the points of the set it is compared with (below). Depth-first
  // with an explicit stack: corners come out in counter-clockwise order, the last line
  // being the first one again.
  constexpr double kSmallestGap = 1e-7;  // sin of the gap; below it a corner is as tight as doubles get
  constexpr double h = std::numbers::sqrt2 / 2;
  static const Vec2 kInitial[] = {{1, 0}, {h, h}, {0, 1}, {-h, h}, {-1, 0}, {-h, -h}, {0, -1}, {h, -h}};
  const SupportLine first = ellipses.support(kInitial[0]);
  Polygon outer;
  outer.reserve(32);
  std::vector<SupportLine> pending;  // lines still to visit, the next one at the back
  pending.reserve(64);
  pending.push_back(first);
  for (int k = 7; k >= 1; --k) pending.push_back(ellipses.support(kInitial[k]));
  SupportLine current = first;
  while (!pending.empty()) {
    const SupportLine& next = pending.back();
    const Vec2 q = corner(current, next);
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
  return outer;
}

}  // namespace covtrack::client
