#pragma once
// From the locomotive's along-track interval to one pose with covariance per vehicle.
//
// The along-track Gaussian has its 99% interval on [lo, hi]. A small shift ds along the
// track moves a vehicle by the body-frame twist (track tangent, and the turn rate per
// metre times ds), so the covariance is sigma_s^2 J J^T (J = body_rate) plus the track
// model's own error. On a curve a long interval also sags off the tangent line
// (curvature * h^2 / 2 for half-width h), which the lateral variance takes in.
#include <cstdint>
#include <string>
#include <vector>

#include "covtrack/devices/driver.hpp"
#include "dead_reckoning.hpp"
#include "track_layout.hpp"

namespace covtrack::lenz {

// Along-track standard deviation whose 99% interval is [lo, hi].
double along_track_sigma(const AlongTrack& a, const PoseModelParams& params);

// Covariance (BODY convention) of a vehicle at s with along-track sigma.
Mat6 vehicle_covariance(const TrackLayout& layout, double s, double sigma_s, const PoseModelParams& params);

// One sample per vehicle, sensor = vehicle name. LOST: `last` poses with +inf diagonal.
// `last` is updated with the poses reported.
std::vector<PoseSample> train_poses(const TrackLayout& layout, const AlongTrack& along,
                                    const PoseModelParams& params, const std::string& parent_frame,
                                    std::int64_t time_us, std::vector<Pose>& last);

}  // namespace covtrack::lenz
