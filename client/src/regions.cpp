#include <cmath>
#include <limits>

#include "covtrack/client/regions.hpp"

namespace covtrack::client {

namespace {

// min over the ellipse of n . x: the ellipse lies in {x : n . x >= inner_support}.
double inner_support(const Vec2& n, const Vec2& center, const Mat2& shape) {
  return n.dot(center) - std::sqrt(std::max(n.dot(shape * n), 0.0));
}

struct HalfPlane {
  Vec2 normal;    // unit, pointing out of the object
  double offset;  // keep normal . x <= offset
};

// The line tangent to both ellipses with both on its outer side, for the hull edge a -> b.
// Its normal is the outward edge normal n0 turned by theta in (-pi/2, pi/2), and solves
//   f(n) = inner_support_a(n) - inner_support_b(n) = 0.
// f is positively homogeneous in n, so with m(t) = n0 + t n1 (n1 = n0 turned by +90 deg,
// t = tan theta) the root needs no trigonometry; safeguarded Newton finds it in a few
// steps. f > 0 towards theta = -pi/2 and f < 0 towards +pi/2 unless one ellipse covers the
// other along the edge; then the tangent to the larger one along n0 is used (both
// ellipses still outside the line: still conservative).
HalfPlane interior_tangent(const Vec2& ca, const Mat2& Sa, const Vec2& cb, const Mat2& Sb) {
  const Vec2 e = cb - ca;
  const Vec2 n0 = Vec2(e.y(), -e.x()).normalized();  // outward for counter-clockwise hulls
  const Vec2 n1(-n0.y(), n0.x());
  const Vec2 d = ca - cb;
  const auto f = [&](const Vec2& m) {
    return m.dot(d) - std::sqrt(std::max(m.dot(Sa * m), 0.0)) +
           std::sqrt(std::max(m.dot(Sb * m), 0.0));
  };
  double t = 0;
  if (f(-n1) > 0 && f(n1) < 0) {
    // Root bracket in t, widened to infinity on the open side.
    double lo = -std::numeric_limits<double>::infinity(), hi = -lo;
    for (int it = 0; it < 60; ++it) {
      const Vec2 m = n0 + t * n1;
      const double sa = std::sqrt(std::max(m.dot(Sa * m), 1e-300));
      const double sb = std::sqrt(std::max(m.dot(Sb * m), 1e-300));
      const double g = m.dot(d) - sa + sb;
      (g > 0 ? lo : hi) = t;
      const double dg = n1.dot(d) - n1.dot(Sa * m) / sa + n1.dot(Sb * m) / sb;
      double next = t - g / dg;
      if (!(next > lo && next < hi)) {  // Newton left the bracket: bisect (in t or theta)
        next = std::isfinite(lo) && std::isfinite(hi) ? 0.5 * (lo + hi)
               : std::isfinite(lo)                    ? std::max(2 * lo, lo + 1)
                                                      : std::min(2 * hi, hi - 1);
      }
      const bool done = std::abs(next - t) <= 1e-12 * (1 + std::abs(t));
      t = next;
      if (done) break;
    }
  }
  const Vec2 n = (n0 + t * n1).normalized();
  // The min makes the line conservative even where the root is inexact.
  return {n, std::min(inner_support(n, ca, Sa), inner_support(n, cb, Sb))};
}

}  // namespace

Polygon contract_region(std::span<const ProjectedVertex> hull, const RegionOptions& o) {
  const std::size_t k = hull.size();
  if (k < 3) return {};  // a point or a segment has no interior to keep
  const double s2 = std::pow(confidence_scale(o.confidence), 2);

  // Start from a box well around the hull; the half-planes cut it down.
  Eigen::AlignedBox2d box;
  for (const ProjectedVertex& v : hull) box.extend(v.mean_px);
  const double margin = box.diagonal().norm() + 1.0;
  Polygon region = {box.min() - Vec2(margin, margin), Vec2(box.max().x() + margin, box.min().y() - margin),
                    box.max() + Vec2(margin, margin), Vec2(box.min().x() - margin, box.max().y() + margin)};
  for (std::size_t i = 0; i < k && !region.empty(); ++i) {
    const ProjectedVertex& a = hull[i];
    const ProjectedVertex& b = hull[(i + 1) % k];
    const HalfPlane h =
        interior_tangent(a.mean_px, s2 * a.covariance_px2, b.mean_px, s2 * b.covariance_px2);
    region = clip_half_plane(region, h.normal, h.offset);
  }
  // A sliver left by rounding is no region.
  if (region.size() < 3 || polygon_area(region) <= 1e-9) return {};
  return region;
}

}  // namespace covtrack::client
