#include "track_layout.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

namespace covtrack::lenz {
namespace {

double horizontal_length(const Segment& g) {
  if (g.kind == SegmentKind::Arc) return g.radius_m * std::abs(g.angle_rad);
  return std::sqrt(std::max(0.0, g.length_m * g.length_m - g.rise_m * g.rise_m));
}

double track_length(const Segment& g) {
  if (g.kind == SegmentKind::Straight) return g.length_m;
  const double h = horizontal_length(g);
  return std::sqrt(h * h + g.rise_m * g.rise_m);  // a helix for an arc that climbs
}

double angle_difference(double a, double b) { return std::remainder(a - b, 2 * std::numbers::pi); }

}  // namespace

double Train::offset_behind_m(std::size_t k) const {
  double offset = 0;
  for (std::size_t i = 1; i <= k && i < vehicles.size(); ++i)
    offset += vehicles[i - 1].length_m / 2 + vehicles[i].gap_m + vehicles[i].length_m / 2;
  return offset;
}

std::string TrackLayout::build(TrackLayout& layout, Vec3 origin_m, double heading_rad,
                               std::vector<Section> sections, Train train) {
  layout = TrackLayout{};
  Vec3 at = origin_m;
  double heading = heading_rad;
  double s = 0;
  for (auto& section : sections) {
    section.start_s = s;
    for (const auto& g : section.segments) {
      Placed p{g, s, track_length(g), at, heading};
      layout.placed_.push_back(p);
      double end_heading = heading;
      at = layout.position_in(p, 1.0, &end_heading, nullptr);
      heading = end_heading;
      s += p.length_m;
    }
    section.length_m = s - section.start_s;
  }
  layout.sections_ = std::move(sections);
  layout.train_ = std::move(train);
  layout.length_m_ = s;
  const double gap_m = (at - origin_m).norm();
  const double turn_deg = angle_difference(heading, heading_rad) * 180 / std::numbers::pi;
  if (gap_m > 0.01 || std::abs(turn_deg) > 1.0)
    return fmt::format("the loop does not close: its last segment ends {:.3f} m from the origin, "
                       "turned {:.1f} degrees from the start heading", gap_m, turn_deg);
  return {};
}

Vec3 TrackLayout::position_in(const Placed& p, double u, double* heading_out, Vec3* tangent_out) const {
  const Segment& g = p.segment;
  const double h0 = p.heading_rad;
  Vec3 pos;
  double heading = h0;
  if (g.kind == SegmentKind::Straight) {
    const double hl = horizontal_length(g) * u;
    pos = p.start_m + Vec3(std::cos(h0) * hl, std::sin(h0) * hl, g.rise_m * u);
  } else {
    const double side = g.angle_rad >= 0 ? 1.0 : -1.0;
    const double theta = g.angle_rad * u;
    const Vec3 centre = p.start_m + side * g.radius_m * Vec3(-std::sin(h0), std::cos(h0), 0);
    heading = h0 + theta;
    pos = centre + side * g.radius_m * Vec3(std::sin(heading), -std::cos(heading), 0);
    pos.z() = p.start_m.z() + g.rise_m * u;
  }
  if (heading_out) *heading_out = heading;
  if (tangent_out) {
    *tangent_out = Vec3(std::cos(heading) * horizontal_length(g), std::sin(heading) * horizontal_length(g), g.rise_m);
    tangent_out->normalize();
  }
  return pos;
}

double TrackLayout::wrap(double s) const {
  const double w = std::fmod(s, length_m_);
  return w < 0 ? w + length_m_ : w;
}

std::size_t TrackLayout::section_at(double s) const {
  const double w = wrap(s);
  for (std::size_t i = 0; i < sections_.size(); ++i)
    if (w < sections_[i].end_s()) return i;
  return sections_.size() - 1;
}

Pose TrackLayout::pose_at(double s) const {
  const double w = wrap(s);
  auto it = std::upper_bound(placed_.begin(), placed_.end(), w,
                             [](double v, const Placed& p) { return v < p.start_s; });
  const Placed& p = *std::prev(it == placed_.begin() ? std::next(it) : it);
  const double u = p.length_m > 0 ? std::clamp((w - p.start_s) / p.length_m, 0.0, 1.0) : 0.0;
  Vec3 tangent;
  const Vec3 pos = position_in(p, u, nullptr, &tangent);
  Vec3 up = Vec3::UnitZ() - tangent.z() * tangent;
  up.normalize();
  Mat3 R;
  R.col(0) = tangent;
  R.col(1) = up.cross(tangent);
  R.col(2) = up;
  Pose T = Pose::Identity();
  T.linear() = R;
  T.translation() = pos;
  return T;
}

Vec6 TrackLayout::body_rate(double s) const {
  // Central difference: exact enough for straight and arc segments, and simple at the
  // joints between them.
  const double h = 1e-4;
  return (boxminus(pose_at(s + h), pose_at(s - h))) / (2 * h);
}

}  // namespace covtrack::lenz
