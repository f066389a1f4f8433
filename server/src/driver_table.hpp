#pragma once
// The central, explicit table of driver types the daemon can host. Adding a driver means
// adding one row here; drivers never know about each other.
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/driver.hpp"

namespace covtrack::server {

// Makes a fresh driver for each (re)start; the argument counts restarts.
using DriverFactory = std::function<std::unique_ptr<Driver>(std::uint64_t run_index)>;

struct DriverType {
  std::string_view type;     // the `type` key of a [devices.<name>] table
  std::string_view summary;  // one line for --help and the schema document
  std::vector<const TableSpec*> specs;  // the device table's spec first, then sub-tables
  // Reads the device table (already checked against specs.front()) into a factory.
  std::function<DriverFactory(TableReader& device, const std::string& name)> read;
};

const std::vector<DriverType>& driver_types();
const DriverType* find_driver_type(std::string_view type);

}  // namespace covtrack::server
