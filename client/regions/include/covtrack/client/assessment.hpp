#pragma once
// Assessment (dissertation 5.3, docs/background.md): one number per object for the size of
// its registration error. A metric turns each projected hull vertex into a value; an
// aggregator turns the vertices and their values into the object's number. Both are plain
// std::function, so applications plug in their own.
#include <functional>
#include <span>

#include "covtrack/client/projection.hpp"

namespace covtrack::client {

// Scale from a 1-sigma covariance ellipse to the one holding `probability` of a 2-D
// Gaussian: sqrt of the chi-square (2 dof) quantile, sqrt(-2 ln(1 - p)). 0.95 -> 2.4477.
double confidence_scale(double probability);

// Semi-axes (1 sigma, px) and the major axis' angle of a 2x2 covariance.
struct EllipseAxes {
  double major_px = 0;
  double minor_px = 0;
  double angle_rad = 0;  // of the major axis, from +u towards +v
};
EllipseAxes ellipse_axes(const Mat2& covariance_px2);
// ellipse_axes(C).major_px, cheaper (no angle).
double ellipse_semi_major_px(const Mat2& covariance_px2);

using VertexMetric = std::function<double(const ProjectedVertex&)>;
using Aggregator =
    std::function<double(std::span<const ProjectedVertex> vertices, std::span<const double> values)>;

struct Assessment {
  VertexMetric metric;
  Aggregator aggregate;
};

// Metrics.
VertexMetric largest_semi_axis_px(double confidence = 0.95);
VertexMetric ellipse_area_px2(double confidence = 0.95);
// Aggregators.
Aggregator max_value();
Aggregator mean_value();
// The value of the vertex whose mean pixel is nearest to `point_px` (e.g. the cursor).
Aggregator nearest_vertex_to(const Vec2& point_px);

// Largest 95% semi-axis over the vertices: "how many pixels can it be off".
Assessment default_assessment();

// +infinity if any vertex is unusable (its error is unknown, so unbounded); NaN if empty.
double assess(const Assessment& assessment, std::span<const ProjectedVertex> vertices);

}  // namespace covtrack::client
