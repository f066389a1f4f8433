#include "covtrack/client/convex_polygon.hpp"

#include <algorithm>
#include <cmath>

#include "plane_cross.hpp"

namespace covtrack::client {
namespace {

// An x-monotone chain, x ascending; evaluated at ascending x with a moving index.
struct Chain {
  std::vector<Vec2> points;
  std::size_t segment = 0;

  double at(double x) {
    while (segment + 2 < points.size() && points[segment + 1].x() < x) ++segment;
    const Vec2& a = points[segment];
    const Vec2& b = points[std::min(segment + 1, points.size() - 1)];
    const double dx = b.x() - a.x();
    if (dx <= 0) return a.y();
    const double t = std::clamp((x - a.x()) / dx, 0.0, 1.0);
    return a.y() + t * (b.y() - a.y());
  }
};

struct Chains {
  Chain lower, upper;
  double x_min = 0, x_max = 0;
};

// Walks counter-clockwise from `from` to `to` (inclusive).
std::vector<Vec2> walk(const Polygon& p, std::size_t from, std::size_t to) {
  std::vector<Vec2> out;
  for (std::size_t i = from;; i = (i + 1) % p.size()) {
    out.push_back(p[i]);
    if (i == to) break;
  }
  return out;
}

Chains split_into_chains(const Polygon& p) {
  // Counter-clockwise with y up, the walk from the leftmost vertex runs along the bottom.
  // Ties at the extreme x (vertical edges) belong to neither chain.
  std::size_t lower_left = 0, lower_right = 0, upper_left = 0, upper_right = 0;
  const auto less = [](const Vec2& a, const Vec2& b, double y_sign) {
    return a.x() < b.x() || (a.x() == b.x() && y_sign * a.y() < y_sign * b.y());
  };
  for (std::size_t i = 1; i < p.size(); ++i) {
    if (less(p[i], p[lower_left], 1)) lower_left = i;
    if (less(p[i], p[upper_left], -1)) upper_left = i;
    if (less(p[lower_right], p[i], -1)) lower_right = i;
    if (less(p[upper_right], p[i], 1)) upper_right = i;
  }
  Chains c;
  c.lower.points = walk(p, lower_left, lower_right);
  c.upper.points = walk(p, upper_right, upper_left);
  std::reverse(c.upper.points.begin(), c.upper.points.end());
  c.x_min = p[lower_left].x();
  c.x_max = p[lower_right].x();
  return c;
}

// The chain's x coordinates inside [lo, hi], ascending, appended.
void append_xs(const Chain& c, double lo, double hi, std::vector<double>& xs) {
  for (const Vec2& p : c.points)
    if (p.x() > lo && p.x() < hi) xs.push_back(p.x());
}

// Drops repeated and (nearly) collinear vertices so the result is a proper polygon.
Polygon simplify(const Polygon& in) {
  Polygon out;
  for (const Vec2& p : in)
    if (out.empty() || (p - out.back()).norm() > 1e-12 * (1 + p.norm())) out.push_back(p);
  while (out.size() > 1 && (out.front() - out.back()).norm() <= 1e-12 * (1 + out.front().norm()))
    out.pop_back();
  bool changed = true;
  while (changed && out.size() >= 3) {
    changed = false;
    for (std::size_t i = 0; i < out.size() && out.size() >= 3; ++i) {
      const Vec2& a = out[(i + out.size() - 1) % out.size()];
      const Vec2& b = out[i];
      const Vec2& c = out[(i + 1) % out.size()];
      if (std::abs(cross(a, b, c)) <= 1e-12 * (b - a).norm() * (c - b).norm() + 1e-18) {
        out.erase(out.begin() + static_cast<std::ptrdiff_t>(i));
        changed = true;
      }
    }
  }
  if (out.size() < 3 || polygon_area(out) <= 0) return {};
  return out;
}

struct Sample {
  double x, lo, hi;
};

}  // namespace

Polygon intersect_convex(const Polygon& a, const Polygon& b) {
  if (a.size() < 3 || b.size() < 3) return {};
  Chains ca = split_into_chains(a), cb = split_into_chains(b);
  const double x0 = std::max(ca.x_min, cb.x_min), x1 = std::min(ca.x_max, cb.x_max);
  if (!(x0 < x1)) return {};

  // Slab boundaries: one linear merge of the four ascending coordinate lists.
  std::vector<double> xs = {x0}, merged;
  for (Chain* c : {&ca.lower, &ca.upper, &cb.lower, &cb.upper}) {
    std::vector<double> these;
    append_xs(*c, x0, x1, these);
    merged.clear();
    std::merge(xs.begin(), xs.end(), these.begin(), these.end(), std::back_inserter(merged));
    xs.swap(merged);
  }
  xs.push_back(x1);
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());

  // Within a slab every chain is straight: max/min of the chains change shape only where
  // two lower (or two upper) chains cross, so those crossings become samples too.
  std::vector<Sample> samples;
  double la0 = ca.lower.at(xs[0]), lb0 = cb.lower.at(xs[0]);
  double ua0 = ca.upper.at(xs[0]), ub0 = cb.upper.at(xs[0]);
  samples.push_back({xs[0], std::max(la0, lb0), std::min(ua0, ub0)});
  for (std::size_t i = 1; i < xs.size(); ++i) {
    const double la1 = ca.lower.at(xs[i]), lb1 = cb.lower.at(xs[i]);
    const double ua1 = ca.upper.at(xs[i]), ub1 = cb.upper.at(xs[i]);
    double ts[3];
    int n = 0;
    const double dl0 = la0 - lb0, dl1 = la1 - lb1, du0 = ua0 - ub0, du1 = ua1 - ub1;
    if (dl0 * dl1 < 0) ts[n++] = dl0 / (dl0 - dl1);
    if (du0 * du1 < 0) ts[n++] = du0 / (du0 - du1);
    std::sort(ts, ts + n);
    ts[n++] = 1.0;
    for (int k = 0; k < n; ++k) {
      const double t = ts[k];
      const auto lerp = [t](double p, double q) { return p + t * (q - p); };
      const double x = k + 1 == n ? xs[i] : lerp(xs[i - 1], xs[i]);
      samples.push_back({x, std::max(lerp(la0, la1), lerp(lb0, lb1)),
                         std::min(lerp(ua0, ua1), lerp(ub0, ub1))});
    }
    la0 = la1, lb0 = lb1, ua0 = ua1, ub0 = ub1;
  }

  // hi - lo is concave in x, so where it is >= 0 is one run of samples; its ends, where
  // the boundaries meet, are interpolated.
  // Where the chains meet exactly (a shared vertex, the slab's end), rounding leaves
  // hi - lo a few ulps below zero: that is a meeting point, not a gap.
  for (Sample& s : samples) {
    const double tol = 1e-12 * (1 + std::abs(s.lo) + std::abs(s.hi));
    if (s.hi < s.lo && s.hi >= s.lo - tol) s.lo = s.hi = 0.5 * (s.lo + s.hi);
  }
  std::vector<Sample> kept;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    const double g = s.hi - s.lo;
    if (i > 0) {
      const Sample& p = samples[i - 1];
      const double gp = p.hi - p.lo;
      if ((gp < 0) != (g < 0) && gp != g) {
        const double t = gp / (gp - g);
        const double x = p.x + t * (s.x - p.x), y = p.lo + t * (s.lo - p.lo);
        if (t > 0 && t < 1) kept.push_back({x, y, y});
      }
    }
    if (g >= 0) kept.push_back(s);
  }
  Polygon out;
  for (const Sample& s : kept) out.emplace_back(s.x, s.lo);
  for (auto it = kept.rbegin(); it != kept.rend(); ++it) out.emplace_back(it->x, it->hi);
  return simplify(out);
}

Vec2 polygon_centroid(const Polygon& p) {
  if (p.empty()) return Vec2::Zero();
  Vec2 mean = Vec2::Zero();
  for (const Vec2& v : p) mean += v;
  mean /= static_cast<double>(p.size());
  // Relative to the mean, so large pixel coordinates do not cancel.
  double twice_area = 0;
  Vec2 sum = Vec2::Zero();
  for (std::size_t i = 0, n = p.size(); i < n; ++i) {
    const Vec2 a = p[i] - mean, b = p[(i + 1) % n] - mean;
    const double w = a.x() * b.y() - a.y() * b.x();
    twice_area += w;
    sum += w * (a + b);
  }
  if (std::abs(twice_area) <= 1e-12) return mean;
  return mean + sum / (3 * twice_area);
}

double polygon_radius(const Polygon& p, const Vec2& center) {
  double r = 0;
  for (const Vec2& v : p) r = std::max(r, (v - center).norm());
  return r;
}

bool is_usable_polygon(const Polygon& p) {
  if (p.size() < 3) return false;
  for (const Vec2& v : p)
    if (!v.allFinite()) return false;
  return true;
}

}  // namespace covtrack::client
