#pragma once
// How much a tracked edge may have moved since its last report.
//
// The object may have moved anywhere within a ball of radius v_max * age (and turned by up
// to w_max * age). We model that displacement per axis as uniform on [-r, r], variance
// r^2 / 3. It is conservative: the per-axis variance of a uniform ball is only r^2 / 5,
// and a Gaussian with sigma r/sqrt(3) still puts ~8% outside r per axis, which is the
// price of keeping one Gaussian. The growth is isotropic, so it means the same in the
// body frame as in any other, and it ignores translation-rotation coupling.
#include <cstdint>

#include "covtrack/protocol/se3.hpp"

namespace covtrack::client {

struct MotionBound {
  double max_linear_speed_m_s = 0.0;
  double max_angular_speed_rad_s = 0.0;
};

// The covariance to add to a report `age_s` seconds old (a negative age, from clock skew
// between hosts, counts as zero).
Mat6 staleness_covariance(const MotionBound& bound, double age_s);

}  // namespace covtrack::client
