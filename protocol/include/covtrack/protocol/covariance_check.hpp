#pragma once
// Validity of a received covariance: a client never silently uses a bad one.
#include <optional>
#include <string>

#include "covtrack/protocol/se3.hpp"

namespace covtrack {

enum class CovarianceDefect { NonFinite, Asymmetric, Indefinite };

struct CovarianceProblem {
  CovarianceDefect defect;
  std::string detail;  // which element or eigenvalue, and its value
};

// Symmetry and semi-definiteness are judged relative to the largest diagonal element,
// so that a covariance in mm^2 and one in m^2 meet the same test.
std::optional<CovarianceProblem> check_covariance(const Mat6& cov);

const char* to_string(CovarianceDefect defect);

}  // namespace covtrack
