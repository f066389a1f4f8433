#include "covtrack/client/assessment.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace covtrack::client {

double confidence_scale(double probability) {
  // Every object's regions ask for the same confidence: remember the last one (a log per
  // call was 2% of a frame).
  thread_local double last_probability = std::numeric_limits<double>::quiet_NaN(), last_scale = 0;
  if (probability != last_probability) {
    last_scale = std::sqrt(-2.0 * std::log1p(-probability));
    last_probability = probability;
  }
  return last_scale;
}

EllipseAxes ellipse_axes(const Mat2& C) {
  // Closed form for a symmetric 2x2: no iterative solver per vertex.
  const double a = C(0, 0), b = 0.5 * (C(0, 1) + C(1, 0)), c = C(1, 1);
  const double mid = 0.5 * (a + c), half = std::hypot(0.5 * (a - c), b);
  EllipseAxes e;
  e.major_px = std::sqrt(std::max(mid + half, 0.0));
  e.minor_px = std::sqrt(std::max(mid - half, 0.0));
  e.angle_rad = 0.5 * std::atan2(2 * b, a - c);
  return e;
}

double ellipse_semi_major_px(const Mat2& C) {
  // As ellipse_axes without the angle: an atan2 per vertex was a tenth of a frame.
  const double a = C(0, 0), b = 0.5 * (C(0, 1) + C(1, 0)), c = C(1, 1);
  const double d = 0.5 * (a - c);
  return std::sqrt(std::max(0.5 * (a + c) + std::sqrt(d * d + b * b), 0.0));
}

VertexMetric largest_semi_axis_px(double confidence) {
  const double s = confidence_scale(confidence);
  return [s](const ProjectedVertex& v) { return s * ellipse_semi_major_px(v.covariance_px2); };
}

VertexMetric ellipse_area_px2(double confidence) {
  const double s2 = std::pow(confidence_scale(confidence), 2);
  return [s2](const ProjectedVertex& v) {
    return std::numbers::pi * s2 * std::sqrt(std::max(v.covariance_px2.determinant(), 0.0));
  };
}

Aggregator max_value() {
  return [](std::span<const ProjectedVertex>, std::span<const double> values) {
    double m = -std::numeric_limits<double>::infinity();
    for (double x : values) m = std::max(m, x);
    return m;
  };
}

Aggregator mean_value() {
  return [](std::span<const ProjectedVertex>, std::span<const double> values) {
    double sum = 0;
    for (double x : values) sum += x;
    return sum / static_cast<double>(values.size());
  };
}

Aggregator nearest_vertex_to(const Vec2& point_px) {
  return [point_px](std::span<const ProjectedVertex> vertices, std::span<const double> values) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < vertices.size(); ++i)
      if ((vertices[i].mean_px - point_px).squaredNorm() <
          (vertices[best].mean_px - point_px).squaredNorm())
        best = i;
    return values[best];
  };
}

Assessment default_assessment() { return {largest_semi_axis_px(0.95), max_value()}; }

double assess(const Assessment& assessment, std::span<const ProjectedVertex> vertices) {
  if (vertices.empty()) return std::numeric_limits<double>::quiet_NaN();
  for (const ProjectedVertex& v : vertices)
    if (!v.flags.usable()) return std::numeric_limits<double>::infinity();
  // A buffer kept per thread (no allocation per object), taken out of its pool while the
  // user's metric and aggregator run, so that they may call assess themselves.
  thread_local std::vector<double> pool;
  std::vector<double> values = std::move(pool);
  values.clear();
  for (const ProjectedVertex& v : vertices) values.push_back(assessment.metric(v));
  const double result = assessment.aggregate(vertices, values);
  pool = std::move(values);
  return result;
}

}  // namespace covtrack::client
