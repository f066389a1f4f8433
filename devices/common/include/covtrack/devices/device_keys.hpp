#pragma once
// Keys every [devices.<name>] table has, whatever its driver; each driver's TableSpec
// starts with them so that unknown-key checks see one complete list.
#include <vector>

#include "covtrack/devices/config_reader.hpp"

namespace covtrack {

std::vector<KeySpec> device_common_keys();

}  // namespace covtrack
