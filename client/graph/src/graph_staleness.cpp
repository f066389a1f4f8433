#include "covtrack/client/graph_staleness.hpp"

#include <algorithm>

namespace covtrack::client {

Mat6 staleness_covariance(const MotionBound& bound, double age_s) {
  const double age = std::max(0.0, age_s);
  const double r_m = bound.max_linear_speed_m_s * age;
  const double r_rad = bound.max_angular_speed_rad_s * age;
  Mat6 out = Mat6::Zero();
  out.diagonal().head<3>().setConstant(r_m * r_m / 3.0);
  out.diagonal().tail<3>().setConstant(r_rad * r_rad / 3.0);
  return out;
}

}  // namespace covtrack::client
