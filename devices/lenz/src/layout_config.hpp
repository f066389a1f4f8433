#pragma once
// Reading a track layout file (config/lenz_layout.toml): the loop's sections with their
// occupancy inputs and segments, and the train. Every key is in config/schema.md.
#include <string>
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/lenz/lenz_driver.hpp"
#include "covtrack/protocol/result.hpp"
#include "track_layout.hpp"

namespace covtrack::lenz {

const TableSpec& layout_file_spec();
const TableSpec& layout_train_spec();
const TableSpec& layout_vehicle_spec();
const TableSpec& layout_section_spec();
const TableSpec& layout_segment_spec();

// Every problem as "file:line:column: key: what", all at once.
Result<TrackLayout> load_layout(const std::string& path);

}  // namespace covtrack::lenz
