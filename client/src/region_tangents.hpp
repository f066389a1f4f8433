#pragma once
// Common tangent lines of pairs of confidence ellipses (adjacent vertices of a
// counter-clockwise hull), solved a block of pairs at a time. The inner region (seed 5.5.2)
// needs the line with both ellipses on its outer side, the outer region's shortcut the line
// with both on its inner side.
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

// Where two lines n . x = h (normals less than pi apart) cross: the corners of both regions.
inline Vec2 corner(const Vec2& na, double ha, const Vec2& nb, double hb) {
  const double inverse_det = 1 / (na.x() * nb.y() - na.y() * nb.x());
  return inverse_det * Vec2(ha * nb.y() - hb * na.y(), hb * na.x() - ha * nb.x());
}

}  // namespace covtrack::client
