#pragma once
// The daemon's TOML config, validated completely before anything starts.
#include <optional>
#include <string>
#include <vector>

#include "covtrack/protocol/message_auth.hpp"
#include "covtrack/protocol/result.hpp"
#include "driver_table.hpp"
#include "vrpn_server_config.hpp"

namespace covtrack::server {

struct DaemonSettings {
  std::string lcm_url;  // empty: --lcm-url, else $LCM_DEFAULT_URL, else LCM's default
  double heartbeat_hz = 1.0;
  double restart_backoff_initial_s = 0.5;
  double restart_backoff_max_s = 10.0;
  double stop_timeout_s = 2.0;  // longest wait for the device threads at a stop
  // One publisher per device (device_ownership.hpp): how long a starting daemon listens
  // for another that holds its devices, and whether it publishes them anyway.
  double claim_wait_s = 0.5;
  bool allow_duplicate_publishers = false;
};

struct DeviceConfig {
  std::string name;
  std::string type;
  DriverOptions options;  // what make_driver (driver_factory.hpp) makes a driver from
  std::string parent_frame = "world";  // the device's parent_frame key
};

struct DaemonConfig {
  DaemonSettings daemon;
  std::vector<DeviceConfig> devices;  // enabled devices only
  std::optional<VrpnServerConfig> vrpn_server;
  std::optional<AuthKey> auth_key;  // [auth]: sign every message (docs/authentication.md)
};

// What a config load checks beyond the config itself.
enum class ResourceChecks {
  Skip,  // at start: a missing device may appear later; its driver retries it
  Run,   // --check: every file and folder the devices name must open (devices are not opened)
};

// On failure the error holds every problem found, one per line, each as
// file:line:column: key.path: what is wrong.
Result<DaemonConfig> load_config(const std::string& path, ResourceChecks checks = ResourceChecks::Skip);
Result<DaemonConfig> parse_config(std::string_view toml_text, const std::string& source_name,
                                  ResourceChecks checks = ResourceChecks::Skip);

// The schema of every table the config can hold, as Markdown (config/schema.md).
std::string config_schema_markdown();

}  // namespace covtrack::server
