#pragma once
// Options of the Lenz Digital Plus train tracker (type = "lenz"), read from its
// [devices.<name>] table; the track and train come from a separate layout file.
#include <memory>
#include <string>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/lenz/dead_reckoning.hpp"
#include "covtrack/devices/lenz/track_layout.hpp"
#include "covtrack/devices/lenz/train_poses.hpp"

namespace covtrack::lenz {

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

}  // namespace covtrack::lenz
