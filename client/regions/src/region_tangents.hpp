#pragma once
// Common tangent lines of pairs of confidence ellipses (adjacent vertices of a
// counter-clockwise hull), solved a block of pairs at a time. The inner region
// (contraction) needs the line with both ellipses on its outer side, the outer region's
// shortcut the line with both on its inner side.
#include <vector>

#include "covtrack/client/projection.hpp"
#include "plane_cross.hpp"

namespace covtrack::client {

enum class TangentSide { inner, outer };

// Pairs solved at once: two vectors of 8 with AVX-512, one object's inner and outer lines
// (up to 8 edges) in one call; a half holds one side's edges.
constexpr int kTangentLanes = 16;
constexpr std::size_t kTangentHalf = kTangentLanes / 2;

// A projected vertex's confidence ellipse shape: scale2 (the confidence scale squared) times
// its covariance, made symmetric: xx, xy, yy.
inline Vec3 confidence_shape(const Mat2& C, double scale2) {
  return {scale2 * C(0, 0), scale2 * 0.5 * (C(0, 1) + C(1, 0)), scale2 * C(1, 1)};
}

struct TangentBlock {
  // Inputs per pair (ellipse a, then b counter-clockwise): centres and shapes (the
  // covariance scaled to the confidence: xx, xy, yy), and the side: -1 inner, +1 outer.
  double au[kTangentLanes], av[kTangentLanes], axx[kTangentLanes], axy[kTangentLanes], ayy[kTangentLanes];
  double bu[kTangentLanes], bv[kTangentLanes], bxx[kTangentLanes], bxy[kTangentLanes], byy[kTangentLanes];
  double side[kTangentLanes];
  // Outputs per pair: the unit normal, pointing out of the object, and the offset of the
  // half-plane n . x <= offset; solved is 0 where one ellipse reaches past the other along
  // the edge, so that no such tangent exists (then the line is along the edge normal).
  double nu[kTangentLanes], nv[kTangentLanes], offset[kTangentLanes], solved[kTangentLanes];
};

// Inner: the ellipses lie in n . x >= offset' for the line's own offset, and offset is the
// smaller of their inner supports, so the half-plane never reaches into either. Outer: the
// larger of their supports, so the half-plane holds both.
void common_tangents(TangentBlock& block);

// One edge's line from a block: normal . x <= offset (see common_tangents).
struct TangentLine {
  Vec2 normal;
  double offset;
  bool solved;
};

// A hull's pixel covariances as structure-of-arrays (centre u, v; covariance xx, xy, yy),
// repeated cyclically past the k hull vertices, so that the ellipses of a block's edges
// (a = i, b = i + 1) are whole runs, copied a vector at a time. Each side scales them to its
// own confidence as they are copied: the outer region's scale is the whole object's, the
// inner's a vertex's (regions.hpp).
struct HullEllipses {
  std::size_t k = 0;
  std::vector<double> u, v, xx, xy, yy;
};

// The lines of every hull edge i (vertex i -> i + 1, cyclic) on each side asked for (a
// null side is skipped), the ellipses scaled by inner_scale2 and outer_scale2 (confidence
// scales squared). Both sides of up to 8 edges share a block.
void hull_tangents(const HullEllipses& ellipses, double inner_scale2, double outer_scale2,
                   std::vector<TangentLine>* inner, std::vector<TangentLine>* outer);

// The same from the hull's vertices: vertex(i) gives the const ProjectedVertex& of hull
// vertex i < k. A point or a segment (k < 3) has no edges to give lines: the sides asked
// for come back empty.
template <class HullVertex>
void hull_tangents(std::size_t k, HullVertex vertex, double inner_scale2, double outer_scale2,
                   std::vector<TangentLine>* inner, std::vector<TangentLine>* outer) {
  if (k < 3) {
    for (auto* lines : {inner, outer})
      if (lines) lines->clear();
    return;
  }
  thread_local HullEllipses e;  // kept per thread: no allocation per object
  // Whole halves of blocks, and the last edge's end.
  const std::size_t entries = (k + kTangentHalf - 1) / kTangentHalf * kTangentHalf + 1;
  e.k = k;
  for (auto* column : {&e.u, &e.v, &e.xx, &e.xy, &e.yy}) column->resize(entries);
  for (std::size_t i = 0, vi = 0; i < entries; ++i, vi = vi + 1 == k ? 0 : vi + 1) {
    const ProjectedVertex& p = vertex(vi);
    const Vec3 S = confidence_shape(p.covariance_px2, 1.0);
    e.u[i] = p.mean_px.x(), e.v[i] = p.mean_px.y();
    e.xx[i] = S[0], e.xy[i] = S[1], e.yy[i] = S[2];
  }
  hull_tangents(e, inner_scale2, outer_scale2, inner, outer);
}

// One side at one scale.
template <class HullVertex>
void hull_tangents(std::size_t k, HullVertex vertex, double scale2, std::vector<TangentLine>* inner,
                   std::vector<TangentLine>* outer) {
  hull_tangents(k, vertex, scale2, scale2, inner, outer);
}

// Where two lines n . x = h (normals less than pi apart) cross: the corners of both regions.
inline Vec2 corner(const Vec2& na, double ha, const Vec2& nb, double hb) {
  const double inverse_det = 1 / cross(na, nb);
  return inverse_det * Vec2(ha * nb.y() - hb * na.y(), hb * na.x() - ha * nb.x());
}

}  // namespace covtrack::client
