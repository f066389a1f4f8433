#pragma once
// The Lenz Digital Plus train tracker: occupancy feedback from an LI101F or LI-USB over
// a serial port, dead reckoning between section boundaries, one pose stream per vehicle.
//
// At (re)connection it asks for the interface version, the command-station version and
// status, and the state of every feedback module the layout uses; a status request every
// keepalive_s keeps the link alive. When the port goes away or falls silent the vehicles
// are reported LOST and the port is reopened until it comes back. Two cases return an
// error, so that the daemon marks the device FAILED and restarts it: a port that cannot
// be opened at the very start, and a line that delivers bytes but no answer to the
// status request for no_valid_frames_s ("no valid frames for N s": noise, a wrong baud
// rate, another device on the port).
//
// Its options (type = "lenz"), read from the [devices.<name>] table, with the track and
// train from a separate layout file (config/lenz_layout.toml, every key in
// config/schema.md), and the LI-USB's USB ids.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"

namespace covtrack::lenz {

// The LI-USB is an FTDI FT232 (a plain RS-232 adapter may carry the same chip).
inline constexpr std::uint16_t kLiUsbVendorId = 0x0403;
inline constexpr std::uint16_t kLiUsbProductId = 0x6001;

class TrackLayout;

struct DeadReckoningParams {
  double crossing_latency_s = 0.05;  // a crossing is detected at most this late
};

struct PoseModelParams {
  double track_sigma_m = 0.003;    // where the rails really are, per axis
  double track_sigma_rad = 0.01;   // how the vehicle really sits on them, per axis
  double min_sigma_s_m = 0.001;    // along-track floor when the interval closes up
};

enum class Interface { Li101f, LiUsb };

struct LenzConfig {
  std::string device;
  std::string parent_frame = "world";
  std::string port;
  Interface interface = Interface::Li101f;
  int baud = 19200;
  bool rts_cts = true;
  std::string layout_path;
  std::shared_ptr<const TrackLayout> layout;
  double rate_hz = 20;
  double keepalive_s = 0.5;
  double link_timeout_s = 1.5;
  // No status reply for this long while bytes arrive: the line is noise, the device has
  // failed (the daemon restarts it). Default: twice link_timeout_s.
  double no_valid_frames_s = 3.0;
  double reconnect_s = 0.25;
  DeadReckoningParams reckoning;
  PoseModelParams pose_model;
};

const TableSpec& lenz_device_spec();

// Reads the options and loads the layout (a relative path is taken from the config
// file's folder); problems go to the reader's error list.
LenzConfig read_lenz_config(TableReader& device, const std::string& device_name);

// The layout file's tables, for the config checks and the key list.
std::vector<const TableSpec*> layout_specs();

// Every time the driver works with (keepalives, timeouts, the sample schedule, dead
// reckoning, the stamps on its poses) comes from `clock`.
std::unique_ptr<Driver> make_lenz_driver(const LenzConfig& config, DriverClock& clock = real_clock());

}  // namespace covtrack::lenz
