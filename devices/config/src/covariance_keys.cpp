#include "covtrack/devices/covariance_keys.hpp"

#include <fmt/format.h>

#include "covtrack/protocol/covariance_check.hpp"

namespace covtrack {

std::vector<KeySpec> covariance_keys() {
  return {
      {"sigma_m", ValueType::FloatArray, "m", "", "1-sigma position error x y z (body frame); "
       "with sigma_rad, or give covariance", 0, 10, 3},
      {"sigma_rad", ValueType::FloatArray, "rad", "", "1-sigma rotation error about x y z "
       "(body frame)", 0, 3.2, 3},
      {"covariance", ValueType::FloatArray, "m^2, m*rad, rad^2", "",
       "full 6x6 row-major, BODY convention; instead of sigma_m and sigma_rad", -100, 100, 36},
  };
}

Mat6 read_covariance(TableReader& r) {
  const Mat6 placeholder = Mat6::Identity() * 1e-6;
  const bool full = r.has("covariance");
  const bool sigmas = r.has("sigma_m") || r.has("sigma_rad");
  if (full == sigmas) {
    r.error(full ? "covariance" : "sigma_m",
            "give either covariance (6x6) or both sigma_m and sigma_rad, not both or neither");
    return placeholder;
  }
  if (full) {
    const auto v = r.numbers("covariance");
    if (v.size() != 36) return placeholder;  // already reported
    const Mat6 cov = Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(v.data());
    if (const auto problem = check_covariance(cov)) {
      r.error("covariance", fmt::format("{}: {}", to_string(problem->defect), problem->detail));
      return placeholder;
    }
    return cov;
  }
  if (!r.has("sigma_m") || !r.has("sigma_rad")) {
    r.error(r.has("sigma_m") ? "sigma_m" : "sigma_rad", "both sigma_m and sigma_rad are needed");
    return placeholder;
  }
  const auto sm = r.numbers("sigma_m");
  const auto sr = r.numbers("sigma_rad");
  if (sm.size() != 3 || sr.size() != 3) return placeholder;  // already reported
  Mat6 cov = Mat6::Zero();
  for (int i = 0; i < 3; ++i) {
    cov(i, i) = sm[i] * sm[i];
    cov(i + 3, i + 3) = sr[i] * sr[i];
  }
  return cov;
}

}  // namespace covtrack
