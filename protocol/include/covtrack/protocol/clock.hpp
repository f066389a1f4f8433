#pragma once
#include <cstdint>

namespace covtrack {

// The time base on the wire: CLOCK_REALTIME in microseconds since the Unix epoch,
// the same clock LCM log timestamps use.
std::int64_t now_us();

}  // namespace covtrack
