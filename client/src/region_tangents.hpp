#pragma once
// Common tangent lines of pairs of confidence ellipses (adjacent vertices of a
// counter-clockwise hull), solved a block of pairs at a time. The inner region (seed 5.5.2)
// needs the line with both ellipses on its outer side, the outer region's shortcut the line
// with both on its inner side.
#include <algorithm>
#include <vector>

#include "covtrack/client/regions.hpp"

namespace covtrack::client {

constexpr int kTangentPairs = 8;

enum class TangentSide { inner, outer };

struct TangentBlock {
  // Inputs per pair (ellipse a, then b counter-clockwise): centres and shapes (the
  // covariance scaled to the confidence: xx, xy, yy).
  double au[kTangentPairs], av[kTangentPairs], axx[kTangentPairs], axy[kTangentPairs], ayy[kTangentPairs];
  double bu[kTangentPairs], bv[kTangentPairs], bxx[kTangentPairs], bxy[kTangentPairs], byy[kTangentPairs];
  // Outputs per pair: the unit normal, pointing out of the object, and the offset of the
  // half-plane n . x <= offset; solved is 0 where one ellipse reaches past the other along
  // the edge, so that no such tangent exists (then the line is along the edge normal).
  double nu[kTangentPairs], nv[kTangentPairs], offset[kTangentPairs], solved[kTangentPairs];
};

// Pair j of the block from two projected vertices; `scale2` = the confidence scale squared.
void set_tangent_pair(TangentBlock& block, int j, const ProjectedVertex& a,
                      const ProjectedVertex& b, double scale2);

// Inner: the ellipses lie in n . x >= offset' for the line's own offset, and offset is the
// smaller of their inner supports, so the half-plane never reaches into either. Outer: the
// larger of their supports, so the half-plane holds both.
void common_tangents(TangentBlock& block, TangentSide side);

// One edge's line from a block: normal . x <= offset (see common_tangents).
struct TangentLine {
  Vec2 normal;
  double offset;
  bool solved;
};

// The line of every hull edge i (vertex(i) -> vertex(i + 1), cyclic; vertex(i) gives a
// const ProjectedVertex&), solved a block of edges at a time.
template <class HullVertex>
void hull_tangents(std::size_t k, HullVertex vertex, double scale2, TangentSide side,
                   std::vector<TangentLine>& lines) {
  lines.resize(k);
  TangentBlock block;
  for (std::size_t first = 0; first < k; first += kTangentPairs) {
    const int count = static_cast<int>(std::min<std::size_t>(kTangentPairs, k - first));
    for (int j = 0; j < kTangentPairs; ++j) {  // a short block repeats its first edge
      const std::size_t i = first + (j < count ? j : 0);
      set_tangent_pair(block, j, vertex(i), vertex(i + 1 == k ? 0 : i + 1), scale2);
    }
    common_tangents(block, side);
    for (int j = 0; j < count; ++j)
      lines[first + j] = {Vec2(block.nu[j], block.nv[j]), block.offset[j], block.solved[j] != 0};
  }
}

inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Where two lines n . x = h (normals less than pi apart) cross: the corners of both regions.
inline Vec2 corner(const Vec2& na, double ha, const Vec2& nb, double hb) {
  const double inverse_det = 1 / cross(na, nb);
  return inverse_det * Vec2(ha * nb.y() - hb * na.y(), hb * na.x() - ha * nb.x());
}

}  // namespace covtrack::client
