#pragma once
// What covtrack knows about each tracker model: its static accuracy (vendor spec sheets),
// report rate and reset time. The defaults of the driver and of the emulator.
#include <string_view>

#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::serial6dof {

struct ModelSpec {
  Model model;
  Protocol protocol;
  std::string_view name;
  double sigma_m;                // static position accuracy, RMS, each axis
  Vec3 sigma_rad_parent;         // static orientation accuracy about the source's x y z
  double rate_hz;                // reports per second per station with one station
  bool rate_is_shared;           // the rate is split across active stations (Fastrak)
  double reset_time_s;           // how long a reset takes
  double latency_s;              // from measurement to the first byte on the wire
  double specified_range_m;      // accuracy holds within this distance of the source
};

const ModelSpec& model_spec(Model model);
const char* to_string(Protocol protocol);
Protocol protocol_of(Model model);

// The default BODY covariance of a receiver at orientation R_source_receiver: position
// errors are isotropic; rotation errors are given about the source's axes (IS-900: yaw
// worse than pitch and roll), so they turn into the body frame as R^T D R.
Mat6 default_covariance(const ModelSpec& spec, const Mat3& R_source_receiver);

// Reports per second per station when `stations` receivers are active.
double station_rate_hz(const ModelSpec& spec, int stations);

}  // namespace covtrack::serial6dof
