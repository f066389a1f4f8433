#include "config.hpp"

#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/wire_text.hpp"

namespace covtrack::server {
namespace {

const TableSpec& top_spec() {
  static const TableSpec spec{"(top level)", "daemon",
                              {
                                  {"daemon", ValueType::Table, "", "{}", "daemon settings"},
                                  {"devices", ValueType::Table, "", "",
                                   "one table per device: [devices.<name>]"},
                                  {"vrpn_server", ValueType::Table, "", "none",
                                   "serve chosen streams to VRPN clients: see vrpn_server"},
                                  {"auth", ValueType::Table, "", "none",
                                   "authenticate every message with a shared key: see auth"},
                              }};
  return spec;
}

const TableSpec& daemon_spec() {
  static const TableSpec spec{
      "daemon", "daemon",
      {
          {"lcm_url", ValueType::String, "", "LCM's default",
           "LCM URL to publish on; --lcm-url overrides it"},
          {"heartbeat_hz", ValueType::Float, "Hz", "1", "device status heartbeats per second", 0.1, 100},
          {"restart_backoff_initial_s", ValueType::Float, "s", "0.5",
           "wait before restarting a failed driver; doubles on each failure", 0.01, 3600},
          {"restart_backoff_max_s", ValueType::Float, "s", "10", "longest wait between restarts",
           0.01, 3600},
          {"stop_timeout_s", ValueType::Float, "s", "2",
           "at SIGINT/SIGTERM, longest wait for the device threads; a device still running then "
           "is named and the daemon exits anyway, with code 4", 0.1, 600},
          {"claim_wait_s", ValueType::Float, "s", "0.5",
           "at start, how long to wait for another daemon that already publishes one of the devices "
           "(it answers a claim at once; 0: do not wait, and rely on the heartbeats)", 0, 10},
          {"allow_duplicate_publishers", ValueType::Boolean, "", "false",
           "publish a device that another daemon already publishes (both then publish it, and say "
           "so); false: such a device is not started, and a device claimed first elsewhere is given "
           "up; --allow-duplicate-publishers sets it"},
      }};
  return spec;
}

DaemonSettings read_daemon(TableReader& top) {
  DaemonSettings d;
  const toml::table* t = top.table("daemon");
  if (!t) return d;
  TableReader r(*t, "daemon", daemon_spec(), top.file(), top.errors());
  d.lcm_url = r.string("lcm_url", "");
  d.heartbeat_hz = r.number("heartbeat_hz", d.heartbeat_hz);
  d.restart_backoff_initial_s = r.number("restart_backoff_initial_s", d.restart_backoff_initial_s);
  d.restart_backoff_max_s = r.number("restart_backoff_max_s", d.restart_backoff_max_s);
  d.stop_timeout_s = r.number("stop_timeout_s", d.stop_timeout_s);
  d.claim_wait_s = r.number("claim_wait_s", d.claim_wait_s);
  d.allow_duplicate_publishers = r.boolean("allow_duplicate_publishers", d.allow_duplicate_publishers);
  if (d.restart_backoff_max_s < d.restart_backoff_initial_s)
    r.error("restart_backoff_max_s", "must not be below restart_backoff_initial_s");
  return d;
}

const TableSpec& auth_spec() {
  static const TableSpec spec{
      "auth", "daemon",
      {
          {"key_file", ValueType::String, "", "",
           "shared key (`covtrack keygen FILE` makes one; others must not be able to read it); relative to this "
           "file. Every message then carries a MAC and a counter, and clients given the same key refuse messages "
           "without a valid one, and replays (docs/authentication.md). Read at start: a daemon told to "
           "authenticate never publishes without its key"},
      }};
  return spec;
}

// The key is read now, not only by --check: a daemon told to sign must not start unsigned.
std::optional<AuthKey> read_auth(TableReader& top) {
  const toml::table* t = top.table("auth");
  if (!t) return std::nullopt;
  TableReader r(*t, "auth", auth_spec(), top.file(), top.errors());
  const std::string key_file = r.string("key_file");
  if (key_file.empty()) return std::nullopt;  // missing: reported by string()
  std::filesystem::path p(key_file);
  if (p.is_relative()) p = std::filesystem::path(top.file()).parent_path() / p;
  auto key = load_auth_key(p.string());
  if (!key) {
    r.error("key_file", key.error().message);
    return std::nullopt;
  }
  return *key;
}

// The device's `type`, checked, before its driver's spec is known.
const DriverType* read_type(const toml::table& device, const std::string& path,
                            const std::string& file, ConfigErrors& errors) {
  const toml::node* type = device.get("type");
  std::string known;
  for (const auto& t : driver_types()) known += (known.empty() ? "" : ", ") + std::string(t.type);
  if (!type) {
    errors.add(file, device.source(), path + ".type", "missing required key (one of: " + known + ")");
    return nullptr;
  }
  if (!type->is_string()) {
    errors.add(file, type->source(), path + ".type", "expected string (one of: " + known + ")");
    return nullptr;
  }
  const DriverType* dt = find_driver_type(type->as_string()->get());
  if (!dt)
    errors.add(file, type->source(), path + ".type",
               fmt::format("unknown driver type '{}' (known: {})", type->as_string()->get(), known));
  return dt;
}

void read_devices(TableReader& top, DaemonConfig& out) {
  const toml::table* devices = top.table("devices");
  if (!devices) return;
  if (devices->empty())
    top.error("devices", "no device configured: add a [devices.<name>] table");
  for (const auto& [key, node] : *devices) {
    const std::string name(key.str());
    const std::string path = "devices." + name;
    if (!is_valid_name(name)) {
      top.errors().add(top.file(), key.source(), path,
                       fmt::format("device name must be 1-{} of A-Z a-z 0-9 _ -", kMaxNameLength));
      continue;
    }
    const toml::table* table = node.as_table();
    if (!table) {
      top.errors().add(top.file(), node.source(), path, "expected a table [devices." + name + "]");
      continue;
    }
    // Clients reject a pose whose frame name holds a control character (protocol/README.md).
    if (const auto* frame = (*table)["parent_frame"].as_string(); frame && control_character_at(frame->get()))
      top.errors().add(top.file(), frame->source(), path + ".parent_frame",
                       "must hold no control character (clients would reject every pose)");
    const DriverType* type = read_type(*table, path, top.file(), top.errors());
    if (!type) continue;
    TableReader r(*table, path, *type->specs.front(), top.file(), top.errors());
    DriverOptions options = type->read(r, name);
    const std::string frame = (*table)["parent_frame"].value_or(std::string("world"));
    if (r.boolean("enabled", true)) out.devices.push_back({name, std::string(type->type), std::move(options), frame});
  }
}

}  // namespace

Result<DaemonConfig> parse_config(std::string_view text, const std::string& source_name,
                                  ResourceChecks checks) {
  auto root = parse_toml(text, source_name);
  if (!root) return std::unexpected(root.error());
  ConfigErrors errors;
  TableReader top(*root, "", top_spec(), source_name, errors);
  DaemonConfig out;
  out.daemon = read_daemon(top);
  read_devices(top, out);
  std::map<std::string, std::string> frames;
  for (const auto& d : out.devices) frames[d.name] = d.parent_frame;
  out.vrpn_server = read_vrpn_server(top, frames);
  out.auth_key = read_auth(top);
  if (checks == ResourceChecks::Run) errors.run_resource_checks();
  if (!errors.empty()) return fail(errors.joined());
  return out;
}

Result<DaemonConfig> load_config(const std::string& path, ResourceChecks checks) {
  auto text = read_config_text(path);
  if (!text) return std::unexpected(text.error());
  return parse_config(*text, path, checks);
}

std::string config_schema_markdown() {
  std::vector<const TableSpec*> tables = {&top_spec(), &daemon_spec(), &vrpn_server_spec(),
                                         &vrpn_server_tracker_spec(), &auth_spec()};
  for (const auto& t : driver_types()) tables.insert(tables.end(), t.specs.begin(), t.specs.end());
  std::string out = "# covtrackd configuration schema\n\n"
                    "Generated by `covtrackd --print-schema`; a test keeps this file equal to "
                    "its output. Units are SI; a config is validated completely before "
                    "anything starts, and every problem is reported as file:line:column.\n\n"
                    "Driver types:\n\n";
  for (const auto& t : driver_types()) out += fmt::format("- `{}`: {}\n", t.type, t.summary);
  return out + "\n" + schema_markdown(tables);
}

}  // namespace covtrack::server
