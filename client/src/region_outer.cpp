// The outer region as the polygon of support lines of the hull of the confidence
// ellipses, refined where it is loose (see regions.hpp for the guarantee).
#include <cmath>
#include <numbers>

#include "covtrack/client/regions.hpp"
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

  // The point of ellipse i farthest along n (any length): c + S n / sqrt(n^T S n).
  Vec2 farthest_point(std::size_t i, const Vec2& n) const {
    const Vec2 c(cu_[i], cv_[i]);
    const Vec2 Sn(sxx_[i] * n.x() + sxy_[i] * n.y(), sxy_[i] * n.x() + syy_[i] * n.y());
    const double r = std::sqrt(std::max(n.dot(Sn), 0.0));
    return r > 0 ? Vec2(c + Sn / r) : c;
  }

 private:
  static constexpr std::size_t kBlock = 8;
  std::vector<double> cu_, cv_, sxx_, sxy_, syy_, h_;
};

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Where two support lines (normals less than pi apart) cross.
Vec2 corner(const SupportLine& a, const SupportLine& b) {
  const double inverse_det = 1 / cross(a.normal, b.normal);
  return inverse_det * Vec2(a.offset * b.normal.y() - b.offset * a.normal.y(),
                            b.offset * a.normal.x() - a.offset * b.normal.x());
}

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

}  // namespace

// One clone per instruction set (vector_clones.hpp); flatten inlines the helpers, so the
// supports' loop is compiled for the clone's instructions too.
[[gnu::flatten]] COVTRACK_VECTOR_CLONES
void expand_region(std::span<const ProjectedVertex> vertices, const RegionOptions& o,
                   Polygon& outer) {
  outer.clear();
  if (vertices.empty()) return;
  const double s2 = std::pow(confidence_scale(o.confidence), 2);
  thread_local Ellipses ellipses;
  ellipses.assign(vertices, s2);
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
}

Polygon expand_region(std::span<const ProjectedVertex> vertices, const RegionOptions& o) {
  Polygon outer;
  expand_region(vertices, o, outer);
  return outer;
}

}  // namespace covtrack::client
