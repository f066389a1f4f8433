#pragma once
// The simulated tracker (type = "sim"): N sensors on a moving rig, reporting poses whose
// noise is drawn from exactly the covariance they report, plus the noise-free truth.
// Its options, read from its [devices.<name>] table, and its factory.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "covtrack/devices/config_reader.hpp"
#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::sim {

enum class MotionKind { Static, Circle, FigureEight, RandomWalk, Waypoints };

struct MotionConfig {
  MotionKind kind = MotionKind::Circle;
  Vec3 center_m = Vec3(0, 0, 1.5);
  double radius_m = 0.5;             // circle radius, figure-eight half width, walk bound
  double period_s = 4.0;             // one lap
  double walk_sigma_m = 0.05;        // random walk: position diffusion per sqrt(s)
  double walk_sigma_rad = 0.1;       // random walk: rotation diffusion per sqrt(s)
  std::vector<Vec3> waypoints_m;     // closed loop
  double speed_mps = 0.5;            // along the waypoint path
  double sensor_spacing_m = 0.1;     // sensors i > 0 sit this far apart along y
};

struct SimConfig {
  std::string device;
  std::string parent_frame = "world";
  std::vector<std::string> sensors;
  double rate_hz = 100;
  MotionConfig motion;
  Mat6 covariance = Mat6::Zero();  // BODY convention; the noise is drawn from exactly this
  std::uint64_t seed = 1;
  double dropout_every_s = 0;      // 0: never
  double dropout_duration_s = 0;
  bool publish_truth = true;
  double inject_failure_every_s = 0;  // 0: never
};

const TableSpec& sim_device_spec();
const TableSpec& sim_motion_spec();

// Reads the sim options; problems go to the reader's error list.
SimConfig read_sim_config(TableReader& device, const std::string& device_name);

// `run_index` counts restarts, so that a restarted driver draws fresh noise. Its samples
// are timed by `clock` (tests run it on simulated time).
std::unique_ptr<Driver> make_sim_driver(const SimConfig& config, std::uint64_t run_index,
                                        DriverClock& clock = real_clock());

}  // namespace covtrack::sim
