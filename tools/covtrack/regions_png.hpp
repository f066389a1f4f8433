#pragma once
// A picture of a RegionsReport at the camera's resolution, in the seed's colours: error
// ellipses blue, outer regions green, inner regions white, mean vertices grey.
#include <string>

#include "covtrack/protocol/result.hpp"
#include "regions_report.hpp"

namespace covtrack::cli {

Result<void> write_regions_png(const RegionsReport& report, const std::string& path);

}  // namespace covtrack::cli
