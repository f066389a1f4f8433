#pragma once
// Screen-space error regions of an object (dissertation 5.2-5.5, docs/background.md).
//
//  - Error ellipse per vertex at a confidence p, drawn as a polygon that CONTAINS it: the
//    image of a regular N-gon circumscribed about the unit circle (vertices at radius
//    1/cos(pi/N)) under the ellipse's affine map. Each polygon vertex is A u / cos(pi/N)
//    for a point A u on the ellipse, so the polygon lies within
//        a (1/cos(pi/N) - 1)          (a = semi-major axis)
//    of the ellipse; N is the smallest count meeting RegionOptions::max_polygon_error_px.
//  - Outer region (expansion, 5.5.1): the convex hull of the ellipses, as the
//    intersection of its support half-planes {n . x <= h(n)}, h(n) = max over the ellipses
//    of n . c + sqrt(n^T S n). compute_object_regions scales the ellipses by the whole
//    object's quantile (whole_object_scale2), so that the WHOLE object, every vertex and
//    edge at once, lies in it with probability >= p (docs/regions.md: the argument and the
//    Monte Carlo checks); at one vertex's scale (expand_region alone, or
//    RegionOptions::whole_object false) each vertex alone does. Directions start 45 degrees apart; a gap is split while the corner
//    of its two lines is farther than max_polygon_error_px from the chord between their
//    contact points and, when one ellipse touches both lines, from that ellipse's point
//    facing the corner (both lie inside the hull), so every corner, hence every point of
//    the polygon, is within that distance of the hull. This costs a few dozen support
//    evaluations per object instead of a hull over every ellipse's polygon (region_outer.cpp).
//    Usually a shortcut applies first: the lines are the common outer tangents of adjacent
//    mean hull vertices' ellipses and, between them, each ellipse's own supports at
//    directions spaced by its curvature; it is kept only when every line holds every
//    ellipse and every corner passes the same distance test, so the guarantee is the same.
//  - Inner region (contraction, 5.5.2): for each edge of the hull of the mean vertices, the
//    line tangent to both adjacent ellipses on the interior side; the region is the
//    intersection of the interior half-planes. Where the published construction (corners =
//    intersections of consecutive tangent lines, then their hull) is well formed, the two
//    are the same polygon, and it is used when checks show that (each line turns left of
//    the last by less than pi and keeps an edge of positive length); otherwise the
//    half-planes clip a box, which stays right when tangent lines become redundant or
//    cross, and is empty when the errors swamp the object. Each tangent is
//    solved by Newton's method until the two ellipses' supports agree to 1e-7 px, or for
//    one last step from 1e-3 px (quadratic convergence lands far closer; a test checks
//    1e-5 px); the line is then moved to the smaller support, so what is left of that
//    error only shrinks the region.
// Polygons (polygon.hpp) are counter-clockwise in (u, v) arithmetic (positive signed
// area), no repeated closing vertex.
#include <span>
#include <vector>

#include "covtrack/client/assessment.hpp"
#include "covtrack/client/polygon.hpp"
#include "covtrack/client/projection.hpp"

namespace covtrack::client {

// ---- Ellipses (region_ellipse.cpp) ----
// Smallest N in [min_sides, max_sides] with a (1/cos(pi/N) - 1) <= max_error_px.
int circumscribed_polygon_sides(double semi_major_px, double max_error_px, int min_sides,
                                int max_sides);
// The ellipse {x : (x-c)^T C^-1 (x-c) <= scale^2} circumscribed by an N-gon.
Polygon circumscribed_ellipse_polygon(const Vec2& center_px, const Mat2& covariance_px2,
                                      double scale, int sides);

struct RegionOptions {
  double confidence = 0.95;
  // Every corner of the outer region lies within this distance of the hull of the
  // confidence ellipses...
  double max_polygon_error_px = 0.5;
  int max_outer_corners = 256;  // ...unless this cap is hit (enormous ellipses)
  // Build the outer region from the mean hull's tangents and arcs where every check allows
  // (region_outer.cpp); the general search otherwise, or always when false. Both give the
  // guarantee above; the shortcut is about 1.4x faster on typical objects.
  bool outer_by_arcs = true;
  // compute_object_regions: scale the outer region so that it holds the WHOLE object with
  // probability >= confidence (whole_object_scale2); false: each vertex's ellipse at the
  // confidence, which holds each vertex alone (a whole object only in fewer draws).
  bool whole_object = true;
};

// ---- The outer region's scale for a whole object (region_scale.cpp) ----
// The quantile of a chi-square distribution with 6 degrees of freedom (the pose's).
double chi2_6_quantile(double probability);
// The squared confidence scale of the outer region of an object whose mean hull (indices
// into `projected`, counter-clockwise) is mean_hull, so that the hull of every vertex's
// ellipse at this scale holds every point of the object at once with probability >= the
// confidence: a simultaneous bound. Between the one-point value chi2_2(p) = -2 ln(1 - p)
// (a point, or vertices moving together) and chi2_6(p) (the pose's own confidence
// ellipsoid, which maps inside every point's ellipse at that scale):
//     2 ln(L / (2 pi (1 - p))),
// L the length of the curve that the hull vertices' whitened error directions trace
// round the region (region_scale.cpp), 2 pi for a point. First order in the pose, from
// the mean pose's Jacobians (pixel_jacobian_wrt_perturbation) and the projected
// covariances.
double whole_object_scale2(const Camera& camera, const UncertainPose& T_camera_object,
                           std::span<const Vec3> vertices_object, std::span<const ProjectedVertex> projected,
                           std::span<const int> mean_hull, double confidence);

// ---- Expansion and contraction (regions.cpp) ----
Polygon expand_region(std::span<const ProjectedVertex> vertices, const RegionOptions& options);
// The same into `outer` (cleared first; no allocation once its capacity suffices).
void expand_region(std::span<const ProjectedVertex> vertices, const RegionOptions& options,
                   Polygon& outer);
// The same given the counter-clockwise hull of the means (indices into `vertices`, as
// convex_hull_indices gives), which compute_object_regions has at hand.
void expand_region(std::span<const ProjectedVertex> vertices, std::span<const int> mean_hull,
                   const RegionOptions& options, Polygon& outer);
// `hull` = the vertices of the convex hull of the means, counter-clockwise.
Polygon contract_region(std::span<const ProjectedVertex> hull, const RegionOptions& options);
void contract_region(std::span<const ProjectedVertex> hull, const RegionOptions& options,
                     Polygon& inner);

// ---- One object (region_object.cpp) ----
struct ObjectRegionOptions {
  ProjectionOptions projection;
  RegionOptions regions;
  Assessment assessment = default_assessment();
};

struct ObjectRegions {
  std::vector<ProjectedVertex> vertices;  // one per input vertex, same order
  std::vector<int> hull;                  // indices of the mean hull, counter-clockwise
  Polygon outer;                          // empty when !valid
  // The confidence scale of the outer region's ellipses (sqrt of whole_object_scale2, or
  // of chi2_2(p) without RegionOptions::whole_object); 0 when !valid.
  double outer_scale = 0;
  Polygon inner;                          // empty when !valid or swamped by the error
  double assessment = 0;                  // of the hull vertices; +inf when !valid
  // OR over all vertices; not_finite also where the regions themselves overflowed.
  ProjectionFlags flags;
  // Every vertex usable (in front of the camera under all sigma points, bounded pose,
  // finite numbers) and the regions finite: only then do the regions mean anything.
  bool valid = false;
};

// The 3-D vertices are used as given (e.g. the object's 3-D hull, precomputed once per
// object); no 3-D hull is computed here.
ObjectRegions compute_object_regions(const Camera& camera, const UncertainPose& T_camera_object,
                                     std::span<const Vec3> vertices_object,
                                     const ObjectRegionOptions& options = {});
// The same into `regions`: an application that keeps one per object and recomputes it
// every frame allocates nothing once the capacities suffice.
void compute_object_regions(const Camera& camera, const UncertainPose& T_camera_object,
                            std::span<const Vec3> vertices_object,
                            const ObjectRegionOptions& options, ObjectRegions& regions);

}  // namespace covtrack::client
