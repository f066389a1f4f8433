#pragma once
// The keys that give a 6x6 covariance in a config table: either per-axis sigmas
// (sigma_m, sigma_rad) or a full matrix (covariance, BODY convention), never both.
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack {

std::vector<KeySpec> covariance_keys();

// The covariance the table gives; problems (both or neither form, an invalid matrix)
// go to the reader's errors and a small placeholder comes back.
Mat6 read_covariance(TableReader& r);

}  // namespace covtrack
