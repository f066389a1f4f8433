#include "vrpn_server_config.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cctype>
#include <set>

#include <fmt/format.h>

#include "covtrack/protocol/channels.hpp"
#include "covtrack/vrpn/message_names.hpp"
#include "covtrack/vrpn/system_messages.hpp"

namespace covtrack::server {
namespace {

// A name a VRPN client can write before '@': no '@', no space, nothing unprintable.
bool is_tracker_name(const std::string& name) {
  return vrpn::is_valid_vrpn_name(name) && std::all_of(name.begin(), name.end(), [](unsigned char c) {
           return std::isalnum(c) || c == '_' || c == '-' || c == '.';
         });
}

struct Stream {
  std::string device, sensor;
};
std::optional<Stream> split_stream(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) return std::nullopt;
  Stream s{text.substr(0, slash), text.substr(slash + 1)};
  if (!is_valid_name(s.device) || !is_valid_name(s.sensor)) return std::nullopt;
  return s;
}

VrpnTrackerConfig read_tracker(TableReader& r, const std::map<std::string, std::string>& device_frames) {
  VrpnTrackerConfig t;
  t.name = r.string("name");
  if (r.has("name") && !is_tracker_name(t.name))
    r.error("name", fmt::format("'{}' is no VRPN device name (1-{} of A-Z a-z 0-9 _ - .)", t.name,
                                vrpn::kMaxVrpnNameLength));
  t.streams = r.strings("streams");
  if (r.has("streams") && t.streams.empty()) r.error("streams", "lists no stream");
  std::string first_stream;
  std::set<std::string> seen;
  for (const auto& text : t.streams) {
    const auto stream = split_stream(text);
    if (!stream) {
      r.error("streams", fmt::format("'{}' is no stream: write \"device/sensor\"", text));
      continue;
    }
    if (!seen.insert(text).second) {
      r.error("streams", fmt::format("'{}' is listed twice (one sensor number each)", text));
      continue;
    }
    const auto frame = device_frames.find(stream->device);
    if (frame == device_frames.end()) {
      r.error("streams", fmt::format("'{}': no enabled device '{}' in [devices]", text, stream->device));
      continue;
    }
    if (first_stream.empty()) {
      first_stream = text;
      t.frame = frame->second;
    } else if (frame->second != t.frame) {
      r.error("streams", fmt::format("'{}' (frame '{}') and '{}' (frame '{}') are in different frames: "
                                     "a VRPN tracker serves one frame, so give each frame its own tracker",
                                     first_stream, t.frame, text, frame->second));
    }
  }
  return t;
}

}  // namespace

const TableSpec& vrpn_server_spec() {
  static const TableSpec spec{
      "vrpn_server", "daemon",
      {
          {"address", ValueType::String, "", "\"0.0.0.0\"",
           "the IPv4 address to listen on (\"127.0.0.1\": this host only; \"0.0.0.0\": every interface)"},
          {"port", ValueType::Integer, "", "3883",
           "TCP port for clients, and UDP port for VRPN's connection requests (VRPN's default is 3883)", 1,
           65535},
          {"udp", ValueType::Boolean, "", "true",
           "answer VRPN's UDP connection requests (a client opening \"Tracker0@host\" without \"tcp://\" "
           "sends one) and send such clients their reports over UDP, as VRPN does"},
          {"max_clients", ValueType::Integer, "", "16", "connections served at once; more are refused", 1, 1000},
          {"max_queued_bytes", ValueType::Integer, "B", "262144",
           "a client with more bytes than this waiting to be sent (it does not read) is disconnected", 1024,
           64 * 1024 * 1024},
          {"trackers", ValueType::TableArray, "", "",
           "the VRPN trackers served: see vrpn_server.trackers"},
      }};
  return spec;
}

const TableSpec& vrpn_server_tracker_spec() {
  static const TableSpec spec{
      "vrpn_server.trackers", "daemon",
      {
          {"name", ValueType::String, "", "",
           "the VRPN device name; clients open \"<name>@host\" (VRPN names are case-sensitive)"},
          {"streams", ValueType::StringArray, "", "",
           "the streams served, as \"device/sensor\"; the first is VRPN sensor 0, the next 1, and so on. "
           "All must share one parent frame; the covariance stays on LCM"},
      }};
  return spec;
}

std::optional<VrpnServerConfig> read_vrpn_server(TableReader& top,
                                                 const std::map<std::string, std::string>& device_frames) {
  const toml::table* table = top.table("vrpn_server");
  if (!table) return std::nullopt;
  TableReader r(*table, "vrpn_server", vrpn_server_spec(), top.file(), top.errors());
  VrpnServerConfig c;
  c.address = r.string("address", c.address);
  if (in_addr parsed{}; inet_pton(AF_INET, c.address.c_str(), &parsed) != 1)
    r.error("address", fmt::format("'{}' is no IPv4 address (VRPN speaks IPv4 only)", c.address));
  c.port = static_cast<int>(r.integer("port", c.port));
  c.udp = r.boolean("udp", c.udp);
  c.max_clients = static_cast<int>(r.integer("max_clients", c.max_clients));
  c.max_queued_bytes = static_cast<std::size_t>(r.integer("max_queued_bytes", static_cast<std::int64_t>(c.max_queued_bytes)));
  std::set<std::string> names;  // one error per repeated tracker, not one per pair
  for (const toml::table* t : r.tables("trackers")) {
    TableReader tr(*t, fmt::format("vrpn_server.trackers[{}]", c.trackers.size()), vrpn_server_tracker_spec(),
                   top.file(), top.errors());
    VrpnTrackerConfig tracker = read_tracker(tr, device_frames);
    if (!names.insert(tracker.name).second) tr.error("name", fmt::format("tracker '{}' is served twice", tracker.name));
    c.trackers.push_back(std::move(tracker));
  }
  if (r.has("trackers") && c.trackers.empty()) r.error("trackers", "serves no tracker: add [[vrpn_server.trackers]]");
  return c;
}

}  // namespace covtrack::server
