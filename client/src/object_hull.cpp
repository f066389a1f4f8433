#include "covtrack/client/object_hull.hpp"

#include <algorithm>
#include <cstdio>
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

// Qhull for the full-rank case. Its messages go to a memory stream so a failure can be
// reported as text rather than printed.
Result<std::vector<int>> qhull_vertices(std::span<const Vec3> points) {
  std::vector<coordT> coords;
  coords.reserve(points.size() * 3);
  for (const Vec3& p : points) coords.insert(coords.end(), {p.x(), p.y(), p.z()});

  char* messages = nullptr;
  std::size_t messages_size = 0;
  FILE* err = open_memstream(&messages, &messages_size);
  qhT qh_struct;
  qhT* qh = &qh_struct;
  qh_zero(qh, err);
  char options[] = "qhull Qt";  // triangulated output; vertices are what we need
  const int code = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False,
                                options, nullptr, err);
  std::vector<int> ids;
  if (code == 0) {
    vertexT* vertex;
    FORALLvertices ids.push_back(qh_pointid(qh, vertex->point));
  }
  qh_freeqhull(qh, !qh_ALL);
  int still_long = 0, still_total = 0;
  qh_memfreeshort(qh, &still_long, &still_total);
  std::fclose(err);
  const std::string text(messages ? messages : "");
  std::free(messages);
  if (code != 0) return fail(fmt::format("3-D convex hull failed (qhull {}): {}", code, text));
  std::sort(ids.begin(), ids.end());
  return ids;
}

}  // namespace

Result<std::vector<int>> convex_hull_indices_3d(std::span<const Vec3> points) {
  if (points.empty()) return fail("3-D convex hull of no points");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!points[i].allFinite()) return fail(fmt::format("vertex {} is not finite", i));

  // The principal axes tell the set's dimension: qhull needs a full-rank set.
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Mat3 scatter = Mat3::Zero();
  for (const Vec3& p : points) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(scatter);  // ascending eigenvalues
  const Eigen::Vector3d spread = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  const double extent = spread(2);
  if (extent == 0) return std::vector<int>{0};
  const auto axis = [&](int k) -> Vec3 { return eig.eigenvectors().col(k); };

  if (spread(1) <= kFlatness * extent) {  // on a line: its two ends
    std::vector<double> along;
    for (const Vec3& p : points) along.push_back(axis(2).dot(p - mean));
    const auto [lo, hi] = std::minmax_element(along.begin(), along.end());
    std::vector<int> ends = {int(lo - along.begin()), int(hi - along.begin())};
    std::sort(ends.begin(), ends.end());
    return ends;
  }
  if (spread(0) <= kFlatness * extent) {  // in a plane: the 2-D hull there
    std::vector<Vec2> in_plane;
    for (const Vec3& p : points) in_plane.emplace_back(axis(2).dot(p - mean), axis(1).dot(p - mean));
    std::vector<int> ids = convex_hull_indices(in_plane);
    std::sort(ids.begin(), ids.end());
    return ids;
  }
  return qhull_vertices(points);
}

}  // namespace covtrack::client
