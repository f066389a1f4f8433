#include "covtrack/devices/lenz/lenz_driver.hpp"

#include <filesystem>

#include <fmt/format.h>

#include "covtrack/devices/device_keys.hpp"
#include "covtrack/devices/serial/baud_rate.hpp"
#include "covtrack/devices/valid_frame_watchdog.hpp"
#include "layout_config.hpp"

namespace covtrack::lenz {

const TableSpec& lenz_device_spec() {
  static const TableSpec spec = [] {
    TableSpec s{"devices.<name> (type = \"lenz\")", "lenz driver", device_common_keys()};
    const std::vector<KeySpec> own = {
        {"port", ValueType::String, "", "", "serial device of the LI101F or LI-USB (e.g. /dev/ttyUSB0)"},
        {"interface", ValueType::String, "", "\"li101f\"", "\"li101f\" (RS-232, no prefixes) or \"liusb\" "
         "(FF FE / FF FD prefixes)"},
        {"baud", ValueType::Integer, "baud", "19200 (li101f), 57600 (liusb)", "serial rate; the LI101F "
         "also runs at 38400, 57600, 115200", 1200, 921600},
        {"rts_cts", ValueType::Boolean, "", "true", "RTS/CTS hardware flow control (recommended by Lenz; "
         "false for the LI-USB-Ethernet's USB side)"},
        {"layout", ValueType::String, "", "", "track layout file (sections, segments, train); relative to "
         "this config file's folder"},
        {"rate_hz", ValueType::Float, "Hz", "20", "pose reports per second per vehicle", 0.1, 1000},
        {"keepalive_s", ValueType::Float, "s", "0.5", "period of the command-station status request "
         "that keeps the link alive", 0.05, 30},
        {"link_timeout_s", ValueType::Float, "s", "1.5", "no byte from the interface for this long: "
         "link dead, sensors LOST, reconnect", 0.1, 120},
        no_valid_frames_key("2 x link_timeout_s", "no answer to the status request (sent every keepalive_s) "
                            "for this long, whatever other bytes arrive: the line is noise, the device FAILED "
                            "and restarted (\"no valid frames for N s\")"),
        {"reconnect_s", ValueType::Float, "s", "0.25", "wait between attempts to reopen a lost port", 0.01, 60},
        {"crossing_latency_s", ValueType::Float, "s", "0.05", "a section boundary crossing is reported "
         "at most this late (command station, interface, serial, scheduling); a driver held up over 20 ms "
         "beyond its waits (a stalled daemon) adds the hold-up to what it then reads", 0, 5},
        {"track_sigma_m", ValueType::Float, "m", "0.003", "error of the track model per axis (rails vs "
         "layout geometry)", 0, 1},
        {"track_sigma_rad", ValueType::Float, "rad", "0.01", "error of a vehicle's attitude on the rails "
         "per axis", 0, 1},
    };
    s.keys.insert(s.keys.end(), own.begin(), own.end());
    return s;
  }();
  return spec;
}

LenzConfig read_lenz_config(TableReader& r, const std::string& device_name) {
  LenzConfig c;
  c.device = device_name;
  c.parent_frame = r.string("parent_frame", c.parent_frame);
  c.port = r.string("port");
  const std::string iface = r.choice("interface", {"li101f", "liusb"}, "li101f");
  c.interface = iface == "liusb" ? Interface::LiUsb : Interface::Li101f;
  c.baud = static_cast<int>(r.integer("baud", c.interface == Interface::LiUsb ? 57600 : 19200));
  if (!serial::is_supported_baud(c.baud)) r.error("baud", fmt::format("{} is not a standard serial rate", c.baud));
  if (c.interface == Interface::LiUsb && c.baud != 57600)
    r.error("baud", "the LI-USB runs at 57600 baud only");
  c.rts_cts = r.boolean("rts_cts", true);
  c.rate_hz = r.number("rate_hz", c.rate_hz);
  c.keepalive_s = r.number("keepalive_s", c.keepalive_s);
  c.link_timeout_s = r.number("link_timeout_s", c.link_timeout_s);
  if (c.link_timeout_s <= c.keepalive_s) r.error("link_timeout_s", "must be longer than keepalive_s");
  c.no_valid_frames_s = r.number(kNoValidFramesKey, 2 * c.link_timeout_s);
  if (c.no_valid_frames_s <= c.keepalive_s)
    r.error(kNoValidFramesKey, "must be longer than keepalive_s (a healthy interface answers once per keepalive)");
  c.reconnect_s = r.number("reconnect_s", c.reconnect_s);
  c.reckoning.crossing_latency_s = r.number("crossing_latency_s", c.reckoning.crossing_latency_s);
  c.pose_model.track_sigma_m = r.number("track_sigma_m", c.pose_model.track_sigma_m);
  c.pose_model.track_sigma_rad = r.number("track_sigma_rad", c.pose_model.track_sigma_rad);

  const std::string layout = r.string("layout");
  if (!layout.empty()) {
    std::filesystem::path p(layout);
    if (p.is_relative()) p = std::filesystem::path(r.file()).parent_path() / p;
    c.layout_path = p.string();
    auto loaded = load_layout(c.layout_path);
    if (loaded) c.layout = std::make_shared<const TrackLayout>(std::move(*loaded));
    else r.error("layout", loaded.error().message);
  }
  return c;
}

}  // namespace covtrack::lenz
