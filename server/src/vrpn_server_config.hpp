#pragma once
// The [vrpn_server] section: which streams covtrackd serves to VRPN clients, as which
// trackers (docs/vrpn.md, "covtrackd as a VRPN server").
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "covtrack/devices/config_reader.hpp"

namespace covtrack::server {

struct VrpnTrackerConfig {
  std::string name;                  // the VRPN device name: clients open "<name>@host"
  std::string frame;                 // the parent frame every stream shares
  std::vector<std::string> streams;  // "device/sensor"; the index is the VRPN sensor number
};

struct VrpnServerConfig {
  std::string address = "0.0.0.0";
  int port = 3883;
  bool udp = true;  // VRPN's UDP connection requests, and reports over UDP for such clients
  int max_clients = 16;
  std::size_t max_queued_bytes = 256 * 1024;  // a client with more unsent is disconnected
  std::vector<VrpnTrackerConfig> trackers;
};

const TableSpec& vrpn_server_spec();
const TableSpec& vrpn_server_tracker_spec();

// `device_frames`: each enabled device's parent frame. A stream of no enabled device,
// or streams of one tracker in different frames, are errors naming the streams.
std::optional<VrpnServerConfig> read_vrpn_server(TableReader& top,
                                                 const std::map<std::string, std::string>& device_frames);

}  // namespace covtrack::server
