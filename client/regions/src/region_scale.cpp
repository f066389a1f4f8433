// The outer region's confidence scale for a whole object: a simultaneous bound over every
// point of the object, not one vertex's (regions.hpp says what it guarantees).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "angle_bound.hpp"
#include "covtrack/client/assessment.hpp"
#include "covtrack/client/regions.hpp"
#include "vector_clones.hpp"

namespace covtrack::client {

namespace {

// Edges solved side by side: loops of fixed length without branches over structure-of-
// arrays data, which vectorise (vector_clones.hpp), as the projection's blocks do. A block
// holds kEdges = kEdgeLanes - 1 edges, so that each loop runs over exactly kEdgeLanes
// lanes: with kEdgeLanes edges the vertices' loop needed one lane more, done without
// vectors, and its square root and division waited on each other.
constexpr std::size_t kEdgeLanes = 8;
constexpr std::size_t kEdges = kEdgeLanes - 1;

// A block of hull edges: lane l holds hull vertex first + l (cyclic) and the edge that
// starts there; lane kEdges only the last edge's end (its own edge is computed and not
// used), and lane kEdgeLanes, zero, what that unused edge reads. Per vertex the object
// point, the pixel covariance (xx, xy, yy) and the outward normal of its edge; then M,
// the pixel's derivative by the object-frame point (2x3, rows m0, m1). The pose
// (covariance C, row-major; rotation R, translation t) and the focal lengths too:
// members of one struct, so that the compiler sees that no store into a lane's arrays
// changes them, and vectorises without checks for overlap (it gives up on too many of
// them).
struct EdgeBlock {
  double C[36], R[9], t[3], fx, fy;
  double px[kEdgeLanes + 1], py[kEdgeLanes + 1], pz[kEdgeLanes + 1];
  double sxx[kEdgeLanes + 1], sxy[kEdgeLanes + 1], syy[kEdgeLanes + 1];
  double u[kEdgeLanes + 1], v[kEdgeLanes + 1];  // mean pixels, one more: the normal of lane kEdges's edge
  double nx[kEdgeLanes + 1], ny[kEdgeLanes + 1];
  double m00[kEdgeLanes + 1], m01[kEdgeLanes + 1], m02[kEdgeLanes + 1];
  double m10[kEdgeLanes + 1], m11[kEdgeLanes + 1], m12[kEdgeLanes + 1];
  double length[kEdgeLanes];
};

// Each edge's jump and its end vertex's arc (see whole_object_scale2), into length[e].
// Only angles are taken, and no angle changes when a vector is scaled by a positive
// factor: so the edges' normals are not normalised (a length per edge), and M is the
// pinhole's times the vertex's depth squared (positive on either side of the camera),
// without a division. The lens's distortion bends directions only by its local
// anisotropy, small inside its fold. No edge (a repeated pixel): a zero normal, angles 0.
COVTRACK_VECTOR_CLONES
void edge_lengths(EdgeBlock& h) {
  const double(&C)[36] = h.C, (&R)[9] = h.R, (&t)[3] = h.t, fx = h.fx, fy = h.fy;
  for (std::size_t l = 0; l < kEdgeLanes; ++l) {
    h.nx[l] = h.v[l + 1] - h.v[l], h.ny[l] = h.u[l] - h.u[l + 1];
    const double x = R[0] * h.px[l] + R[1] * h.py[l] + R[2] * h.pz[l] + t[0];
    const double y = R[3] * h.px[l] + R[4] * h.py[l] + R[5] * h.pz[l] + t[1];
    const double z = R[6] * h.px[l] + R[7] * h.py[l] + R[8] * h.pz[l] + t[2];
    h.m00[l] = fx * (z * R[0] - x * R[6]), h.m01[l] = fx * (z * R[1] - x * R[7]), h.m02[l] = fx * (z * R[2] - x * R[8]);
    h.m10[l] = fy * (z * R[3] - y * R[6]), h.m11[l] = fy * (z * R[4] - y * R[7]), h.m12[l] = fy * (z * R[5] - y * R[8]);
  }
  for (std::size_t e = 0; e < kEdgeLanes; ++e) {
    const std::size_t f = e + 1;
    const double nx = h.nx[e], ny = h.ny[e];
    // J^T n = [w, p x w] with w = M^T n, for the edge's two vertices.
    const double wa[3] = {nx * h.m00[e] + ny * h.m10[e], nx * h.m01[e] + ny * h.m11[e], nx * h.m02[e] + ny * h.m12[e]};
    const double wb[3] = {nx * h.m00[f] + ny * h.m10[f], nx * h.m01[f] + ny * h.m11[f], nx * h.m02[f] + ny * h.m12[f]};
    const double a[6] = {wa[0], wa[1], wa[2], h.py[e] * wa[2] - h.pz[e] * wa[1], h.pz[e] * wa[0] - h.px[e] * wa[2],
                         h.px[e] * wa[1] - h.py[e] * wa[0]};
    const double b[6] = {wb[0], wb[1], wb[2], h.py[f] * wb[2] - h.pz[f] * wb[1], h.pz[f] * wb[0] - h.px[f] * wb[2],
                         h.px[f] * wb[1] - h.py[f] * wb[0]};
    double aa = 0, ab = 0, bb = 0;
#pragma GCC unroll 6
    for (int r = 0; r < 6; ++r) {
      double Ca = 0, Cb = 0;
#pragma GCC unroll 6
      for (int c = 0; c < 6; ++c) Ca += C[6 * r + c] * a[c], Cb += C[6 * r + c] * b[c];
      aa += a[r] * Ca, ab += b[r] * Ca, bb += b[r] * Cb;
    }
    // (No jump where a vertex does not move along the normal: aa bb = 0 gives the angle 0.)
    const double jump = angle_at_most(std::sqrt(std::max(aa * bb - ab * ab, 0.0)), std::max(aa * bb, 0.0) > 0 ? ab : 1.0);
    // Vertex e + 1's arc from this edge's normal to the next edge's, in its covariance's metric.
    const double mx = h.nx[f], my = h.ny[f];
    const double turn = std::abs(nx * my - ny * mx);
    const double det = h.sxx[f] * h.syy[f] - h.sxy[f] * h.sxy[f];
    const double dot = nx * (h.sxx[f] * mx + h.sxy[f] * my) + ny * (h.sxy[f] * mx + h.syy[f] * my);
    h.length[e] = jump + angle_at_most(std::sqrt(std::max(det, 0.0)) * turn, dot);
  }
}

}  // namespace

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
  const double per_vertex = std::pow(confidence_scale(confidence), 2);  // chi2_2(p)
  const std::size_t k = mean_hull.size();
  if (k < 2) return per_vertex;  // one point: the region is its ellipse
  EdgeBlock h;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) h.C[6 * r + c] = pose.covariance(r, c);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) h.R[3 * r + c] = pose.T.linear()(r, c);
    h.t[r] = pose.T.translation()[r];
  }
  h.fx = camera.fx, h.fy = camera.fy;
  for (double* spare : {h.px, h.py, h.pz, h.sxx, h.sxy, h.syy, h.nx, h.ny, h.m00, h.m01, h.m02, h.m10, h.m11, h.m12})
    spare[kEdgeLanes] = 0;
  double length = 0;
  for (std::size_t first = 0; first < k; first += kEdges) {
    for (std::size_t l = 0, i = first % k; l <= kEdgeLanes; ++l, i = i + 1 == k ? 0 : i + 1) {
      const ProjectedVertex& pv = projected[mean_hull[i]];
      h.u[l] = pv.mean_px.x(), h.v[l] = pv.mean_px.y();
      if (l == kEdgeLanes) break;
      const Vec3& p = vertices_object[mean_hull[i]];
      h.px[l] = p.x(), h.py[l] = p.y(), h.pz[l] = p.z();
      const Mat2& S = pv.covariance_px2;
      h.sxx[l] = S(0, 0), h.sxy[l] = 0.5 * (S(0, 1) + S(1, 0)), h.syy[l] = S(1, 1);
    }
    edge_lengths(h);
    for (std::size_t l = 0; l < kEdges && first + l < k; ++l) length += h.length[l];
  }
  const double s2 = 2 * std::log(std::max(length, 2 * std::numbers::pi) / (2 * std::numbers::pi)) + per_vertex;
  // Never beyond the bound that holds for every point at once: the 6-D confidence
  // ellipsoid of the pose maps inside every point's ellipse at that scale. That bound too
  // where the length is not a number (a pose covariance far from positive semi-definite).
  const double every_point = chi2_6_quantile(confidence);
  return std::isnan(s2) ? every_point : std::min(s2, every_point);
}

}  // namespace covtrack::client
