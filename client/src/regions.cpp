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
  // f(-n1) > 0 and f(n1) < 0, with n1 . d = -|e| and the supports even in n:
  // |sb(n1) - sa(n1)| < |e|.
  const double edge = e.norm();
  const double sa1 = std::sqrt(std::max(n1.dot(Sa * n1), 0.0));
  const double sb1 = std::sqrt(std::max(n1.dot(Sb * n1), 0.0));
  double t = 0;
  if (std::abs(sb1 - sa1) < edge) {
    // Root bracket in t, widened to infinity on the open side.
    double lo = -std::numeric_limits<double>::infinity(), hi = -lo;
    // Start where f's linear part meets the supports along n0: with n1 . d = -|e|,
    // f(t) ~ -t |e| - sa(n0) + sb(n0): close to the root when the ellipses are small
    // against the edge, so Newton needs two or three steps instead of six.
    t = (std::sqrt(std::max(n0.dot(Sb * n0), 0.0)) - std::sqrt(std::max(n0.dot(Sa * n0), 0.0))) /
        edge;
    for (int it = 0; it < 60; ++it) {
      const Vec2 m = n0 + t * n1;
      const double sa = std::sqrt(std::max(m.dot(Sa * m), 1e-300));
      const double sb = std::sqrt(std::max(m.dot(Sb * m), 1e-300));
      const double g = m.dot(d) - sa + sb;
      // g is in pixels (per unit |m|): the two supports differ by less than 1e-7 px, so the
      // line is tangent to both to that; the min below makes it conservative anyway.
      if (std::abs(g) <= 1e-7 * std::sqrt(m.squaredNorm())) break;
      (g > 0 ? lo : hi) = t;
      const double dg = n1.dot(d) - n1.dot(Sa * m) / sa + n1.dot(Sb * m) / sb;
      double next = t - g / dg;
      if (!(next > lo && next < hi)) {  // Newton left the bracket: bisect (in t or theta)
        next = std::isfinite(lo) && std::isfinite(hi) ? 0.5 * (lo + hi)
               : std::isfinite(lo)                    ? std::max(2 * lo, lo + 1)
                                                      : std::min(2 * hi, hi - 1);
      }
      // 1e-10 in t is 1e-10 rad at the root's angle: far below a pixel at any distance,
      // and the min below keeps the line conservative whatever is left.
      const bool done = std::abs(next - t) <= 1e-10 * (1 + std::abs(t));
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

  // Start from a box well around the hull; the half-planes cut it down. Each cut adds at
  // most one corner, so two buffers of 4 + k corners hold every step (no allocation per cut).
  Eigen::AlignedBox2d box;
  for (const ProjectedVertex& v : hull) box.extend(v.mean_px);
  const double margin = box.diagonal().norm() + 1.0;
  std::vector<Vec2> buffers(2 * (4 + k));
  Vec2* region = buffers.data();
  Vec2* next = region + 4 + k;
  region[0] = box.min() - Vec2(margin, margin);
  region[1] = Vec2(box.max().x() + margin, box.min().y() - margin);
  region[2] = box.max() + Vec2(margin, margin);
  region[3] = Vec2(box.min().x() - margin, box.max().y() + margin);
  std::size_t size = 4;
  for (std::size_t i = 0; i < k && size > 0; ++i) {
    const ProjectedVertex& a = hull[i];
    const ProjectedVertex& b = hull[(i + 1) % k];
    const HalfPlane h =
        interior_tangent(a.mean_px, s2 * a.covariance_px2, b.mean_px, s2 * b.covariance_px2);
    size = clip_half_plane(std::span<const Vec2>(region, size), h.normal, h.offset, next);
    std::swap(region, next);
  }
  // A sliver left by rounding is no region.
  if (size < 3) return {};
  Polygon out(region, region + size);
  if (polygon_area(out) <= 1e-9) return {};
  return out;
}

}  // namespace covtrack::client
