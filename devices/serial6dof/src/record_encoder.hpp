#pragma once
// The device side of the three formats: bytes exactly as a unit sends them. Used by the
// emulators and by tests; the inverse of the decoders.
#include <cstdint>
#include <string>
#include <vector>

#include "fastrak_decoder.hpp"
#include "flock_decoder.hpp"
#include "liberty_decoder.hpp"

namespace covtrack::serial6dof {

using Bytes = std::vector<std::uint8_t>;

// `r.position_m` is converted to the format's units; r.status_code is the status letter
// (' ' when OK). Extras take r.device_time_s and r.buttons (0 when absent).
Bytes encode_fastrak_record(const TrackerRecord& r, const FastrakFormat& format);
// The 55-byte ASCII status record with the units flag set as given.
Bytes encode_fastrak_status(int station, Units units);

Bytes encode_liberty_frame(int station, char command, std::uint8_t error, const Bytes& payload,
                           const char preamble[2] = "LY");
Bytes encode_liberty_record(const TrackerRecord& r, const LibertyFormat& format,
                            const char preamble[2] = "LY");

Bytes encode_flock_record(const TrackerRecord& r, const FlockFormat& format);

}  // namespace covtrack::serial6dof
