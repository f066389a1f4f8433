#include "region_tangents.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "vector_clones.hpp"

namespace covtrack::client {

void set_tangent_pair(TangentBlock& block, int j, const ProjectedVertex& a,
                      const ProjectedVertex& b, double scale2) {
  const auto fill = [&](const ProjectedVertex& v, double& u, double& w, double& xx, double& xy, double& yy) {
    const Mat2& C = v.covariance_px2;
    u = v.mean_px.x(), w = v.mean_px.y();
    xx = scale2 * C(0, 0), xy = scale2 * 0.5 * (C(0, 1) + C(1, 0)), yy = scale2 * C(1, 1);
  };
  fill(a, block.au[j], block.av[j], block.axx[j], block.axy[j], block.ayy[j]);
  fill(b, block.bu[j], block.bv[j], block.bxx[j], block.bxy[j], block.byy[j]);
}

// Pair j's line is tangent to both ellipses a_j and b_j (shapes S). Its normal is the
// outward edge normal n0 turned by theta in (-pi/2, pi/2), and solves
//   f(n) = support_a(n) - support_b(n) = 0,
// with the inner supports min n . x (inner side) or the supports max n . x (outer side).
// f is positively homogeneous in n, so with m(t) = n0 + t n1 (n1 = n0 turned by +90 deg,
// t = tan theta) the root needs no trigonometry; safeguarded Newton finds it in a few
// steps. f > 0 towards theta = -pi/2 and f < 0 towards +pi/2 unless one ellipse reaches
// past the other along the edge; then the line along n0 is used (not solved), its offset
// still conservative.
// All pairs of a block iterate together in loops over the block, which vectorise
// (vector_clones.hpp): one edge's Newton steps are a chain of square roots and divisions
// that would leave the processor waiting.
COVTRACK_VECTOR_CLONES
void common_tangents(TangentBlock& block, TangentSide tangent_side) {
  constexpr int kEdges = kTangentPairs;
  // s = -1 (inner) or +1 (outer): f = m . (a - b) + s (sqrt(m'Sa m) - sqrt(m'Sb m)).
  const double s = tangent_side == TangentSide::inner ? -1.0 : 1.0;
  TangentBlock b = block;  // a local copy: stores cannot alias the inputs
  double n0u[kEdges], n0v[kEdges], du[kEdges], dv[kEdges], t[kEdges], lo[kEdges], hi[kEdges];
  // 1 where an edge is finished: doubles, not bools, so that every array in the loops
  // has the same element size (the vectoriser's requirement).
  double done[kEdges];
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (int j = 0; j < kEdges; ++j) {
    const double eu = b.bu[j] - b.au[j], ev = b.bv[j] - b.av[j];
    const double edge = std::sqrt(eu * eu + ev * ev), inverse_edge = 1 / edge;
    n0u[j] = ev * inverse_edge, n0v[j] = -eu * inverse_edge;  // outward for counter-clockwise hulls
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
    t[j] = solvable ? s * (sa0 - sb0) * inverse_edge : 0.0;
    done[j] = solvable ? 0.0 : 1.0;
    b.solved[j] = solvable ? 1.0 : 0.0;
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
      const double g = mu * du[j] + mv * dv[j] + s * (sa - sb);
      // g is in pixels (per unit |m|): the two supports differ by less than 1e-7 px, so the
      // line is tangent to both to that; the min below makes it conservative anyway.
      // (Compared squared, like the tests below: a square root less per step.)
      const double g2 = g * g, m2 = mu * mu + mv * mv;
      const bool converged = g2 <= 1e-14 * m2;
      const double new_lo = g > 0 ? t[j] : lo[j], new_hi = g > 0 ? hi[j] : t[j];
      // The Newton step g / g', with g' = n1 . d + s (n1'Sa m / sa - n1'Sb m / sb) brought to
      // one division: one instead of three in the chain each step waits for.
      const double sab = sa * sb;
      const double dg_sab = (n1u * du[j] + n1v * dv[j]) * sab + s * ((n1u * Sau + n1v * Sav) * sb - (n1u * Sbu + n1v * Sbv) * sa);
      double next = t[j] - g * sab / dg_sab;
      // Newton left the bracket: bisect (in t, or in theta towards an open side).
      // (Conditions combine with & and |: branch-free, as the vectoriser needs.)
      const bool lo_finite = new_lo > -inf, hi_finite = new_hi < inf;
      const double open_side = lo_finite ? std::max(2 * new_lo, new_lo + 1) : std::min(2 * new_hi, new_hi - 1);
      const double fallback = (lo_finite & hi_finite) ? 0.5 * (new_lo + new_hi) : open_side;
      const bool newton = (next > new_lo) & (next < new_hi);
      next = newton ? next : fallback;
      // 1e-10 in t is 1e-10 rad at the root's angle: far below a pixel at any distance,
      // and the min below keeps the line conservative whatever is left.
      const bool small_step = std::abs(next - t[j]) <= 1e-10 * (1 + std::abs(t[j]));
      // Newton converges quadratically: from a residual under 1e-3 px the step lands within
      // about g^2 (ellipse size) / edge^2, far below 1e-7 px for any edge longer than the
      // ellipses; taking it without evaluating g again saves a whole pass over the block.
      const bool last_step = newton & (g2 <= 1e-6 * m2);
      const bool stop = (done[j] != 0) | converged;
      lo[j] = stop ? lo[j] : new_lo;
      hi[j] = stop ? hi[j] : new_hi;
      t[j] = stop ? t[j] : next;
      done[j] = (stop | small_step | last_step) ? 1.0 : 0.0;
    }
  }
  for (int j = 0; j < kEdges; ++j) {
    double nu = n0u[j] - t[j] * n0v[j], nv = n0v[j] + t[j] * n0u[j];
    const double inverse_len = 1 / std::sqrt(nu * nu + nv * nv);
    nu *= inverse_len, nv *= inverse_len;
    // The smaller inner support (the larger support) makes the line conservative even
    // where the root is inexact.
    const double ra = std::sqrt(std::max(nu * nu * b.axx[j] + 2 * nu * nv * b.axy[j] + nv * nv * b.ayy[j], 0.0));
    const double rb = std::sqrt(std::max(nu * nu * b.bxx[j] + 2 * nu * nv * b.bxy[j] + nv * nv * b.byy[j], 0.0));
    const double ia = nu * b.au[j] + nv * b.av[j] + s * ra, ib = nu * b.bu[j] + nv * b.bv[j] + s * rb;
    block.nu[j] = nu, block.nv[j] = nv, block.solved[j] = b.solved[j];
    block.offset[j] = s < 0 ? std::min(ia, ib) : std::max(ia, ib);
  }
}

}  // namespace covtrack::client
