#include "covtrack/client/object_hull.hpp"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <string>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include "covtrack/client/regions.hpp"

namespace covtrack::client {
namespace {

// Relative spread below which a direction counts as flat (metres per metre of extent).
constexpr double kFlatness = 1e-9;

// Runs qhull on a full-rank set and lets `read` take what it needs before it is freed.
// Its messages go to a memory stream so a failure can be reported as text, not printed.
Result<void> with_qhull(std::span<const Vec3> points, const std::function<void(qhT*)>& read) {
  std::vector<coordT> coords;
  coords.reserve(points.size() * 3);
  for (const Vec3& p : points) coords.insert(coords.end(), {p.x(), p.y(), p.z()});

  char* messages = nullptr;
  std::size_t messages_size = 0;
  FILE* err = open_memstream(&messages, &messages_size);
  qhT qh_struct;
  qhT* qh = &qh_struct;
  qh_zero(qh, err);
  char options[] = "qhull Qt";  // triangulated output
  const int code = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False,
                                options, nullptr, err);
  if (code == 0) read(qh);
  qh_freeqhull(qh, !qh_ALL);
  int still_long = 0, still_total = 0;
  qh_memfreeshort(qh, &still_long, &still_total);
  std::fclose(err);
  const std::string text(messages ? messages : "");
  std::free(messages);
  if (code != 0) return fail(fmt::format("3-D convex hull failed (qhull {}): {}", code, text));
  return {};
}

Result<std::vector<int>> qhull_vertices(std::span<const Vec3> points) {
  std::vector<int> ids;
  auto r = with_qhull(points, [&](qhT* qh) {
    vertexT* vertex;
    FORALLvertices ids.push_back(qh_pointid(qh, vertex->point));
  });
  if (!r) return std::unexpected(r.error());
  std::sort(ids.begin(), ids.end());
  return ids;
}

Result<std::vector<Triangle>> qhull_triangles(std::span<const Vec3> points) {
  std::vector<Triangle> triangles;
  auto r = with_qhull(points, [&](qhT* qh) {
    facetT* facet;
    FORALLfacets {
      Triangle t{};
      int k = 0;
      vertexT *vertex, **vertexp;
      FOREACHvertex_(facet->vertices) if (k < 3) t[k++] = qh_pointid(qh, vertex->point);
      if (k < 3) continue;
      // Counter-clockwise seen from outside: along the facet's outward normal.
      const Vec3 normal(facet->normal[0], facet->normal[1], facet->normal[2]);
      const auto& [a, b, c] = t;
      if ((points[b] - points[a]).cross(points[c] - points[a]).dot(normal) < 0) std::swap(t[1], t[2]);
      triangles.push_back(t);
    }
  });
  if (!r) return std::unexpected(r.error());
  return triangles;
}

// The principal axes of a set (ascending spread), which tell its dimension.
struct PrincipalAxes {
  Vec3 mean;
  Eigen::Vector3d spread;
  Mat3 axes;  // columns, with the spreads' order
};

PrincipalAxes principal_axes(std::span<const Vec3> points) {
  PrincipalAxes out;
  out.mean = Vec3::Zero();
  for (const Vec3& p : points) out.mean += p;
  out.mean /= static_cast<double>(points.size());
  Mat3 scatter = Mat3::Zero();
  for (const Vec3& p : points) scatter += (p - out.mean) * (p - out.mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(scatter);  // ascending eigenvalues
  out.spread = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  out.axes = eig.eigenvectors();
  return out;
}

Result<void> check_finite(std::span<const Vec3> points) {
  if (points.empty()) return fail("3-D convex hull of no points");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) return fail(fmt::format("vertex {} is not finite", i));
  return {};
}

// A flat set's points in its plane, in the plane's two widest axes.
std::vector<Vec2> in_plane(std::span<const Vec3> points, const PrincipalAxes& p) {
  std::vector<Vec2> out;
  for (const Vec3& q : points) out.emplace_back(p.axes.col(2).dot(q - p.mean), p.axes.col(1).dot(q - p.mean));
  return out;
}

}  // namespace

Result<std::vector<int>> convex_hull_indices_3d(std::span<const Vec3> points) {
  if (auto r = check_finite(points); !r) return std::unexpected(r.error());
  const PrincipalAxes p = principal_axes(points);
  const double extent = p.spread(2);
  if (extent == 0) return std::vector<int>{0};

  if (p.spread(1) <= kFlatness * extent) {  // on a line: its two ends
    std::vector<double> along;
    for (const Vec3& q : points) along.push_back(p.axes.col(2).dot(q - p.mean));
    const auto [lo, hi] = std::minmax_element(along.begin(), along.end());
    std::vector<int> ends = {int(lo - along.begin()), int(hi - along.begin())};
    std::sort(ends.begin(), ends.end());
    return ends;
  }
  if (p.spread(0) <= kFlatness * extent) {  // in a plane: the 2-D hull there
    std::vector<int> ids = convex_hull_indices(in_plane(points, p));
    std::sort(ids.begin(), ids.end());
    return ids;
  }
  return qhull_vertices(points);
}

Result<std::vector<Triangle>> convex_hull_triangles_3d(std::span<const Vec3> points) {
  if (auto r = check_finite(points); !r) return std::unexpected(r.error());
  const PrincipalAxes p = principal_axes(points);
  const double extent = p.spread(2);
  if (extent == 0 || p.spread(1) <= kFlatness * extent) return std::vector<Triangle>{};  // a point or a line
  if (p.spread(0) <= kFlatness * extent) {  // in a plane: a fan over its 2-D hull
    const std::vector<int> ring = convex_hull_indices(in_plane(points, p));
    std::vector<Triangle> fan;
    for (std::size_t i = 1; i + 1 < ring.size(); ++i) fan.push_back({ring[0], ring[i], ring[i + 1]});
    return fan;
  }
  return qhull_triangles(points);
}

}  // namespace covtrack::client
