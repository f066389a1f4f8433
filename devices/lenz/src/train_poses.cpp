#include "train_poses.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace covtrack::lenz {

double along_track_sigma(const AlongTrack& a, const PoseModelParams& params) {
  return std::max((a.hi_s - a.lo_s) / (2 * kZ99), params.min_sigma_s_m);
}

Mat6 vehicle_covariance(const TrackLayout& layout, double s, double sigma_s, const PoseModelParams& params) {
  const Vec6 J = layout.body_rate(s);
  Mat6 cov = sigma_s * sigma_s * J * J.transpose();
  const double curvature = J.tail<3>().norm();
  const double half_width = kZ99 * sigma_s;
  const double sag_sigma = curvature * half_width * half_width / 2 / kZ99;
  cov(1, 1) += sag_sigma * sag_sigma;
  for (int i = 0; i < 3; ++i) {
    cov(i, i) += params.track_sigma_m * params.track_sigma_m;
    cov(i + 3, i + 3) += params.track_sigma_rad * params.track_sigma_rad;
  }
  return cov;
}

std::vector<PoseSample> train_poses(const TrackLayout& layout, const AlongTrack& along,
                                    const PoseModelParams& params, const std::string& parent_frame,
                                    std::int64_t time_us, std::vector<Pose>& last) {
  const auto& vehicles = layout.train().vehicles;
  last.resize(vehicles.size(), Pose::Identity());
  std::vector<PoseSample> out;
  for (std::size_t k = 0; k < vehicles.size(); ++k) {
    PoseSample p{vehicles[k].name, parent_frame, vehicles[k].name, time_us};
    if (along.state == AlongTrack::State::Lost) {
      p.status = TrackingStatus::Lost;
      p.T_parent_child = last[k];
      p.covariance = lost_covariance();
    } else {
      const double s = along.mid_s() - layout.train().offset_behind_m(k);
      p.status = TrackingStatus::Degraded;  // dead reckoning, always
      p.T_parent_child = layout.pose_at(s);
      p.covariance = vehicle_covariance(layout, s, along_track_sigma(along, params), params);
      last[k] = p.T_parent_child;
    }
    out.push_back(p);
  }
  return out;
}

}  // namespace covtrack::lenz
