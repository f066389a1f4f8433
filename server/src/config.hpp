#pragma once
// The daemon's TOML config, validated completely before anything starts.
#include <string>
#include <vector>

#include "covtrack/protocol/result.hpp"
#include "driver_table.hpp"

namespace covtrack::server {

struct DaemonSettings {
  std::string lcm_url;  // empty: --lcm-url, else $LCM_DEFAULT_URL, else LCM's default
  double heartbeat_hz = 1.0;
  double restart_backoff_initial_s = 0.5;
  double restart_backoff_max_s = 10.0;
};

struct DeviceConfig {
  std::string name;
  std::string type;
  DriverFactory make;
};

struct DaemonConfig {
  DaemonSettings daemon;
  std::vector<DeviceConfig> devices;  // enabled devices only
};

// On failure the error holds every problem found, one per line, each as
// file:line:column: key.path: what is wrong.
Result<DaemonConfig> load_config(const std::string& path);
Result<DaemonConfig> parse_config(std::string_view toml_text, const std::string& source_name);

// The schema of every table the config can hold, as Markdown (config/schema.md).
std::string config_schema_markdown();

}  // namespace covtrack::server
