// The outer region's confidence scale for a whole object: a simultaneous bound over every
// point of the object, not one vertex's (regions.hpp says what it guarantees).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "covtrack/client/regions.hpp"

namespace covtrack::client {

double chi2_6_quantile(double p) {
  // Every object asks for the same confidence: remember the last one.
  thread_local double last_p = std::numeric_limits<double>::quiet_NaN(), last_x = 0;
  if (p == last_p) return last_x;
  // With six degrees of freedom, P(X > x) = exp(-x/2) (1 + x/2 + x^2/8): Newton on its
  // logarithm, which is close to linear in x; from the two-dimensional quantile plus 4.
  const double target = std::log1p(-p);
  double x = -2 * std::log1p(-p) + 4;
  for (int it = 0; it < 50; ++it) {
    const double poly = 1 + x / 2 + x * x / 8;
    const double f = -x / 2 + std::log(poly) - target;
    const double df = -0.5 + (0.5 + x / 4) / poly;
    const double step = f / df;
    x = std::max(x - step, 1e-12);
    if (std::abs(step) <= 1e-12 * x) break;
  }
  last_p = p;
  last_x = x;
  return x;
}

double whole_object_scale2(const Camera& camera, const UncertainPose& pose,
                           std::span<const Vec3> vertices_object, std::span<const ProjectedVertex> projected,
                           std::span<const int> mean_hull, double confidence) {
  // Whitened by the pose covariance C, each hull vertex i facing the direction n (a unit
  // normal on the screen) is the unit vector u_i(n) along C^(1/2) J_i^T n in R^6 (J_i its
  // pixel Jacobian), and the object leaves the region along n when u . z > scale for the
  // pose's standard normal z. Round the region's boundary u traces a closed curve: over
  // vertex i's arc (normals between its two hull edges') a piece of a great circle, as long
  // as the arc's turn measured in vertex i's own covariance; at an edge, a jump to the next
  // vertex's u, bridged here by the great circle between them (more directions: only
  // conservative). The chance that the largest u . z on a closed curve of length L exceeds
  // s is at most about its expected count of upcrossings, L / (2 pi) exp(-s^2 / 2) (Rice's
  // formula; exact for one point, whose curve is a whole great circle, L = 2 pi). Vertices
  // inside the mean hull are not on the curve: to leave the region they must move farther.
  const double per_vertex = -2 * std::log1p(-confidence);
  const std::size_t k = mean_hull.size();
  if (k < 2) return per_vertex;  // one point: the region is its ellipse
  const Mat6& C = pose.covariance;
  thread_local std::vector<Mat26> jacobians;  // of the hull vertices (no allocation per object)
  thread_local std::vector<Vec2> normals;     // of the hull edges: vertex e -> e + 1, outward
  jacobians.resize(k);
  normals.resize(k);
  for (std::size_t e = 0; e < k; ++e) {
    jacobians[e] = pixel_jacobian_wrt_perturbation(camera, pose.T, vertices_object[mean_hull[e]]);
    const Vec2 d = projected[mean_hull[(e + 1) % k]].mean_px - projected[mean_hull[e]].mean_px;
    const double d_norm = d.norm();
    normals[e] = d_norm > 0 ? Vec2(d.y() / d_norm, -d.x() / d_norm) : Vec2(1, 0);
  }
  double length = 0;
  for (std::size_t e = 0; e < k; ++e) {
    const std::size_t next = (e + 1) % k;
    // The jump at edge e, from vertex e's u to vertex e + 1's along the edge's normal.
    const Vec2& n = normals[e];
    const Vec6 a = jacobians[e].transpose() * n, b = jacobians[next].transpose() * n;
    const Vec6 Ca = C * a;
    const double aa = a.dot(Ca), bb = b.dot(C * b), ab = b.dot(Ca);
    if (aa > 0 && bb > 0) length += std::acos(std::clamp(ab / std::sqrt(aa * bb), -1.0, 1.0));
    // Vertex e + 1's arc, from edge e's normal to edge e + 1's, in the metric of its
    // covariance S: the angle between S^(1/2) n and S^(1/2) n' (at most pi: the hull is convex).
    const Vec2& n_after = normals[next];
    const Mat2& S = projected[mean_hull[next]].covariance_px2;
    const double turn = std::abs(n.x() * n_after.y() - n.y() * n_after.x());
    length += std::atan2(std::sqrt(std::max(S.determinant(), 0.0)) * turn, n.dot(S * n_after));
  }
  const double s2 = 2 * std::log(std::max(length, 2 * std::numbers::pi) / (2 * std::numbers::pi)) + per_vertex;
  // Never beyond the bound that holds for every point at once: the 6-D confidence
  // ellipsoid of the pose maps inside every point's ellipse at that scale.
  return std::min(s2, chi2_6_quantile(confidence));
}

}  // namespace covtrack::client
