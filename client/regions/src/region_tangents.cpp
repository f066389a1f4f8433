#include "region_tangents.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "vector_clones.hpp"

namespace covtrack::client {

// Pair j's line is tangent to both ellipses a_j and b_j (shapes S). Its normal is the
// outward edge normal n0 turned by theta in (-pi/2, pi/2), and solves
//   f(n) = support_a(n) - support_b(n) = 0,
// with the inner supports min n . x (inner side) or the supports max n . x (outer side).
// f is positively homogeneous in n, so the normal m(t) = N0 + t N1 need not be a unit
// vector: with N0 = the edge e turned by -90 degrees and N1 = e (both |e| long, t = tan
// theta) nothing is normalised until the end, and safeguarded Newton finds the root in a
// few steps. f > 0 towards theta = -pi/2 and f < 0 towards +pi/2 unless one ellipse reaches
// past the other along the edge; then the line along n0 is used (not solved), its offset
// still conservative.
// All pairs of a block iterate together in loops over the block, which vectorise
// (vector_clones.hpp). The steps are chains of square roots and divisions, which leave the
// processor waiting, so there are none but the needed: no edge length, no normalising
// before the end.
COVTRACK_VECTOR_CLONES
void common_tangents(TangentBlock& block) {
  constexpr int kEdges = kTangentLanes;
  const TangentBlock& b = block;  // inputs and outputs are different members: no aliasing
  // s = -1 (inner) or +1 (outer): f = m . (a - b) + s (sqrt(m'Sa m) - sqrt(m'Sb m)).
  const double* s = b.side;
  // The normal's parts (N0 = (n0u, n0v), N1 = (-n0v, n0u)), a - b, t and Newton's bracket.
  double n0u[kEdges], n0v[kEdges], du[kEdges], dv[kEdges], t[kEdges], lo[kEdges], hi[kEdges];
  // 1 where an edge is finished: doubles, not bools, so that every array in the loops
  // has the same element size (the vectoriser's requirement).
  double done[kEdges];
  constexpr double inf = std::numeric_limits<double>::infinity();
  // v'Sv for v = (x, y) and S = (xx, xy; xy, yy), not negative.
  const auto quadratic = [](double x, double y, double xx, double xy, double yy) {
    return std::max(x * x * xx + 2 * x * y * xy + y * y * yy, 0.0);
  };
  for (int j = 0; j < kEdges; ++j) {
    const double eu = b.bu[j] - b.au[j], ev = b.bv[j] - b.av[j], e2 = eu * eu + ev * ev;
    n0u[j] = ev, n0v[j] = -eu;  // outward for counter-clockwise hulls
    du[j] = -eu, dv[j] = -ev;   // a - b
    // A root exists when |sb(n1) - sa(n1)| < |e| for the unit n1 (then f(-n1) > 0 and f(n1)
    // < 0): with P, Q the squared supports along N1 = |e| n1, |sqrt(Q) - sqrt(P)| < e2,
    // that is P + Q - e2^2 < 2 sqrt(PQ), squared where the left side is not negative.
    const double P = quadratic(eu, ev, b.axx[j], b.axy[j], b.ayy[j]);
    const double Q = quadratic(eu, ev, b.bxx[j], b.bxy[j], b.byy[j]);
    const double left = P + Q - e2 * e2;
    const bool solvable = (left < 0) | (left * left < 4 * P * Q);
    // Start where f's linear part meets the supports along N0: f(t) ~ -t e2 + s (sa(N0) -
    // sb(N0)), close to the root when the ellipses are small against the edge.
    const double sa0 = std::sqrt(quadratic(n0u[j], n0v[j], b.axx[j], b.axy[j], b.ayy[j]));
    const double sb0 = std::sqrt(quadratic(n0u[j], n0v[j], b.bxx[j], b.bxy[j], b.byy[j]));
    t[j] = solvable ? s[j] * (sa0 - sb0) / e2 : 0.0;
    done[j] = solvable ? 0.0 : 1.0;
    block.solved[j] = solvable ? 1.0 : 0.0;
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
      const double g = mu * du[j] + mv * dv[j] + s[j] * (sa - sb);
      // g / |m| is in pixels: the two supports differ by less than 1e-7 px, so the line is
      // tangent to both to that; the min below makes it conservative anyway. (Compared
      // squared, like the tests below: a square root less per step.)
      const double g2 = g * g, m2 = mu * mu + mv * mv;
      const bool converged = g2 <= 1e-14 * m2;
      const double new_lo = g > 0 ? t[j] : lo[j], new_hi = g > 0 ? hi[j] : t[j];
      // The Newton step g / g', with g' = N1 . d + s (N1'Sa m / sa - N1'Sb m / sb) brought
      // to one division: one instead of three in the chain each step waits for.
      const double sab = sa * sb;
      const double dg_sab = (n1u * du[j] + n1v * dv[j]) * sab + s[j] * ((n1u * Sau + n1v * Sav) * sb - (n1u * Sbu + n1v * Sbv) * sa);
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
    // The supports along the final normal, before it is normalised (they scale with it):
    // the smaller inner support (the larger support) makes the line conservative even
    // where the root is inexact.
    const double mu = n0u[j] - t[j] * n0v[j], mv = n0v[j] + t[j] * n0u[j];
    const double inverse_len = 1 / std::sqrt(mu * mu + mv * mv);
    const double ra = std::sqrt(quadratic(mu, mv, b.axx[j], b.axy[j], b.ayy[j]));
    const double rb = std::sqrt(quadratic(mu, mv, b.bxx[j], b.bxy[j], b.byy[j]));
    const double ia = mu * b.au[j] + mv * b.av[j] + s[j] * ra, ib = mu * b.bu[j] + mv * b.bv[j] + s[j] * rb;
    block.nu[j] = mu * inverse_len, block.nv[j] = mv * inverse_len;
    block.offset[j] = (s[j] < 0 ? std::min(ia, ib) : std::max(ia, ib)) * inverse_len;
  }
}

namespace {

// Half `half` of a block's lanes (0 or 1) from the ellipses of the edges first ..
// first + kTangentHalf - 1 on one side, shapes scaled by scale2. Copies of a constant 8
// doubles are whole vectors.
void fill_half(TangentBlock& block, int half, const HullEllipses& e, std::size_t first, TangentSide side,
               double scale2) {
  const auto copy = [&](double* lanes, const std::vector<double>& column, std::size_t from) {
    std::memcpy(lanes + half * kTangentHalf, column.data() + from, kTangentHalf * sizeof(double));
  };
  const auto scaled = [&](double* lanes, const std::vector<double>& column, std::size_t from) {
    for (std::size_t j = 0; j < kTangentHalf; ++j) lanes[half * kTangentHalf + j] = scale2 * column[from + j];
  };
  copy(block.au, e.u, first), copy(block.bu, e.u, first + 1);
  copy(block.av, e.v, first), copy(block.bv, e.v, first + 1);
  scaled(block.axx, e.xx, first), scaled(block.bxx, e.xx, first + 1);
  scaled(block.axy, e.xy, first), scaled(block.bxy, e.xy, first + 1);
  scaled(block.ayy, e.yy, first), scaled(block.byy, e.yy, first + 1);
  std::fill_n(block.side + half * kTangentHalf, kTangentHalf, side == TangentSide::inner ? -1.0 : 1.0);
}

}  // namespace

// The work goes in halves of a block: kTangentHalf edges of one side. Two halves per block, so
// that an object of up to kTangentHalf edges has both its sides in one block (an odd half out is
// solved twice). Past the k edges a half's lanes hold edges again from the start (the
// ellipses repeat cyclically): real pairs, solved and not used.
COVTRACK_VECTOR_CLONES  // the copies in whole vectors
void hull_tangents(const HullEllipses& e, double inner_scale2, double outer_scale2,
                   std::vector<TangentLine>* inner, std::vector<TangentLine>* outer) {
  struct Half {
    std::vector<TangentLine>* lines;
    TangentSide side;
    std::size_t first;
  };
  thread_local std::vector<Half> halves;
  halves.clear();
  const std::size_t k = e.k;
  for (auto [lines, side] : {std::pair{inner, TangentSide::inner}, std::pair{outer, TangentSide::outer}}) {
    if (!lines) continue;
    lines->resize(k);
    for (std::size_t first = 0; first < k; first += kTangentHalf) halves.push_back({lines, side, first});
  }
  TangentBlock block;
  for (std::size_t h = 0; h < halves.size(); h += 2) {
    const Half* pair[2] = {&halves[h], &halves[h + 1 < halves.size() ? h + 1 : h]};
    for (int half = 0; half < 2; ++half) {
      const Half& w = *pair[half];
      fill_half(block, half, e, w.first, w.side, w.side == TangentSide::inner ? inner_scale2 : outer_scale2);
    }
    common_tangents(block);
    for (int half = 0; half < 2; ++half) {
      const Half& w = *pair[half];
      for (std::size_t j = 0, lane = half * kTangentHalf; j < kTangentHalf && w.first + j < k; ++j, ++lane)
        (*w.lines)[w.first + j] = {Vec2(block.nu[lane], block.nv[lane]), block.offset[lane], block.solved[lane] != 0};
    }
  }
}

}  // namespace covtrack::client
