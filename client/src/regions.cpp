#include <algorithm>
#include <cmath>
#include <limits>

#include "covtrack/client/regions.hpp"
#include "vector_clones.hpp"

namespace covtrack::client {

namespace {

// The interior tangents of a block of hull edges, solved side by side: edge j's line is
// tangent to both ellipses a_j and b_j (scaled covariances S), with both on its outer side.
// Its normal is the outward edge normal n0 turned by theta in (-pi/2, pi/2), and solves
//   f(n) = inner_support_a(n) - inner_support_b(n) = 0.
// f is positively homogeneous in n, so with m(t) = n0 + t n1 (n1 = n0 turned by +90 deg,
// t = tan theta) the root needs no trigonometry; safeguarded Newton finds it in a few
// steps. f > 0 towards theta = -pi/2 and f < 0 towards +pi/2 unless one ellipse covers the
// other along the edge; then the tangent to the larger one along n0 is used (both
// ellipses still outside the line: still conservative).
// All edges of a block iterate together in loops over the block, which vectorise
// (vector_clones.hpp): one edge's Newton steps are a chain of square roots and divisions
// that would leave the processor waiting.
constexpr int kEdges = 8;

struct TangentBlock {
  // Inputs per edge: centres, shapes (xx, xy, yy).
  double au[kEdges], av[kEdges], axx[kEdges], axy[kEdges], ayy[kEdges];
  double bu[kEdges], bv[kEdges], bxx[kEdges], bxy[kEdges], byy[kEdges];
  // Output per edge: unit normal (pointing out of the object) and offset: keep n . x <= offset.
  double nu[kEdges], nv[kEdges], offset[kEdges];
};

COVTRACK_VECTOR_CLONES
void interior_tangents(TangentBlock& block) {
  TangentBlock b = block;  // a local copy: stores cannot alias the inputs
  double n0u[kEdges], n0v[kEdges], du[kEdges], dv[kEdges], t[kEdges], lo[kEdges], hi[kEdges];
  // 1 where an edge is finished: doubles, not bools, so that every array in the loops
  // has the same element size (the vectoriser's requirement).
  double done[kEdges];
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (int j = 0; j < kEdges; ++j) {
    const double eu = b.bu[j] - b.au[j], ev = b.bv[j] - b.av[j];
    const double edge = std::sqrt(eu * eu + ev * ev);
    n0u[j] = ev / edge, n0v[j] = -eu / edge;  // outward for counter-clockwise hulls
    du[j] = -eu, dv[j] = -ev;                 // a - b
    const double n1u = -n0v[j], n1v = n0u[j];
    // f(-n1) > 0 and f(n1) < 0 when |sb(n1) - sa(n1)| < |e| (n1 . d = -|e|, supports even).
    const double sa1 = std::sqrt(std::max(n1u * n1u * b.axx[j] + 2 * n1u * n1v * b.axy[j] + n1v * n1v * b.ayy[j], 0.0));
    const double sb1 = std::sqrt(std::max(n1u * n1u * b.bxx[j] + 2 * n1u * n1v * b.bxy[j] + n1v * n1v * b.byy[j], 0.0));
    // Start where f's linear part meets the supports along n0: f(t) ~ -t |e| - sa(n0) +
    // sb(n0), close to the root when the ellipses are small against the edge.
    const double sa0 = std::sqrt(std::max(n0u[j] * n0u[j] * b.axx[j] + 2 * n0u[j] * n0v[j] * b.axy[j] + n0v[j] * n0v[j] * b.ayy[j], 0.0));
    const double sb0 = std::sqrt(std::max(n0u[j] * n0u[j] * b.bxx[j] + 2 * n0u[j] * n0v[j] * b.bxy[j] + n0v[j] * n0v[j] * b.byy[j], 0.0));
    const bool solvable = std::abs(sb1 - sa1) < edge;
    t[j] = solvable ? (sb0 - sa0) / edge : 0.0;
    done[j] = solvable ? 0.0 : 1.0;
    lo[j] = -inf, hi[j] = inf;
  }
  for (int it = 0; it < 60; ++it) {
    double finished = 0;
    for (int j = 0; j < kEdges; ++j) finished += done[j];
    if (finished == kEdges) break;
    for (int j = 0; j < kEdges; ++j) {
      const double n1u = -n0v[j], n1v = n0u[j];
      const double mu = n0u[j] + t[j] * n1u, mv = n0v[j] + t[j] * n1v;
      const double Sau = b.axx[j] * mu + b.axy[j] * mv, Sav = b.axy[j] * mu + b.ayy[j] * mv;
      const double Sbu = b.bxx[j] * mu + b.bxy[j] * mv, Sbv = b.bxy[j] * mu + b.byy[j] * mv;
      const double sa = std::sqrt(std::max(mu * Sau + mv * Sav, 1e-300));
      const double sb = std::sqrt(std::max(mu * Sbu + mv * Sbv, 1e-300));
      const double g = mu * du[j] + mv * dv[j] - sa + sb;
      // g is in pixels (per unit |m|): the two supports differ by less than 1e-7 px, so the
      // line is tangent to both to that; the min below makes it conservative anyway.
      const bool converged = std::abs(g) <= 1e-7 * std::sqrt(mu * mu + mv * mv);
      const double new_lo = g > 0 ? t[j] : lo[j], new_hi = g > 0 ? hi[j] : t[j];
      const double dg = n1u * du[j] + n1v * dv[j] - (n1u * Sau + n1v * Sav) / sa + (n1u * Sbu + n1v * Sbv) / sb;
      double next = t[j] - g / dg;
      // Newton left the bracket: bisect (in t, or in theta towards an open side).
      // (Conditions combine with & and |: branch-free, as the vectoriser needs.)
      const bool lo_finite = new_lo > -inf, hi_finite = new_hi < inf;
      const double open_side = lo_finite ? std::max(2 * new_lo, new_lo + 1) : std::min(2 * new_hi, new_hi - 1);
      const double fallback = (lo_finite & hi_finite) ? 0.5 * (new_lo + new_hi) : open_side;
      next = ((next > new_lo) & (next < new_hi)) ? next : fallback;
      // 1e-10 in t is 1e-10 rad at the root's angle: far below a pixel at any distance,
      // and the min below keeps the line conservative whatever is left.
      const bool small_step = std::abs(next - t[j]) <= 1e-10 * (1 + std::abs(t[j]));
      const bool stop = (done[j] != 0) | converged;
      lo[j] = stop ? lo[j] : new_lo;
      hi[j] = stop ? hi[j] : new_hi;
      t[j] = stop ? t[j] : next;
      done[j] = (stop | small_step) ? 1.0 : 0.0;
    }
  }
  for (int j = 0; j < kEdges; ++j) {
    double nu = n0u[j] - t[j] * n0v[j], nv = n0v[j] + t[j] * n0u[j];
    const double len = std::sqrt(nu * nu + nv * nv);
    nu /= len, nv /= len;
    // The smaller inner support makes the line conservative even where the root is inexact.
    const double ia = nu * b.au[j] + nv * b.av[j] -
                      std::sqrt(std::max(nu * nu * b.axx[j] + 2 * nu * nv * b.axy[j] + nv * nv * b.ayy[j], 0.0));
    const double ib = nu * b.bu[j] + nv * b.bv[j] -
                      std::sqrt(std::max(nu * nu * b.bxx[j] + 2 * nu * nv * b.bxy[j] + nv * nv * b.byy[j], 0.0));
    block.nu[j] = nu, block.nv[j] = nv, block.offset[j] = std::min(ia, ib);
  }
}

}  // namespace

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
  TangentBlock block;
  const auto fill = [&](const ProjectedVertex& v, double& u, double& w, double& xx, double& xy, double& yy) {
    const Mat2& C = v.covariance_px2;
    u = v.mean_px.x(), w = v.mean_px.y();
    xx = s2 * C(0, 0), xy = s2 * 0.5 * (C(0, 1) + C(1, 0)), yy = s2 * C(1, 1);
  };
  for (std::size_t first = 0; first < k && size > 0; first += kEdges) {
    const int count = static_cast<int>(std::min<std::size_t>(kEdges, k - first));
    for (int j = 0; j < kEdges; ++j) {  // a short block repeats its first edge
      const std::size_t i = first + (j < count ? j : 0);
      fill(hull[i], block.au[j], block.av[j], block.axx[j], block.axy[j], block.ayy[j]);
      fill(hull[(i + 1) % k], block.bu[j], block.bv[j], block.bxx[j], block.bxy[j], block.byy[j]);
    }
    interior_tangents(block);
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
