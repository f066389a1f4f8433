#include "covtrack/devices/sim/sim_driver.hpp"

#include <set>

#include <fmt/format.h>

#include "covtrack/devices/covariance_keys.hpp"
#include "covtrack/devices/device_keys.hpp"
#include "covtrack/protocol/channels.hpp"

namespace covtrack::sim {
namespace {
constexpr int kMaxSimSensors = 64;
}  // namespace

const TableSpec& sim_device_spec() {
  static const TableSpec spec = [] {
    TableSpec s{"devices.<name> (type = \"sim\")", "sim driver", device_common_keys()};
    const std::vector<KeySpec> own = {
        {"sensors", ValueType::StringArray, "", "", "sensor names (child frames); or sensor_count"},
        {"sensor_count", ValueType::Integer, "", "", "N sensors named s0..s(N-1); or sensors", 1, kMaxSimSensors},
        {"rate_hz", ValueType::Float, "Hz", "100", "reports per second per sensor", 0.01, 10000},
        {"seed", ValueType::Integer, "", "1", "noise seed: same seed, same noise", 0, 4e18},
        {"dropout_every_s", ValueType::Float, "s", "0", "a LOST interval ends every this many "
         "seconds (0: never)", 0, 1e6},
        {"dropout_duration_s", ValueType::Float, "s", "0", "length of each LOST interval", 0, 1e6},
        {"publish_truth", ValueType::Boolean, "", "true", "publish noise-free poses on covtrack/truth/..."},
        {"inject_failure_every_s", ValueType::Float, "s", "0", "fault injection: the driver fails "
         "after running this long, to exercise the daemon's restart (0: never)", 0, 1e6},
        {"motion", ValueType::Table, "", "circle", "how the sensors move: see devices.<name>.motion"},
    };
    s.keys.insert(s.keys.end(), own.begin(), own.end());
    const auto cov = covariance_keys();  // the noise is drawn from exactly this covariance
    s.keys.insert(s.keys.end(), cov.begin(), cov.end());
    return s;
  }();
  return spec;
}

const TableSpec& sim_motion_spec() {
  static const TableSpec spec{
      "devices.<name>.motion (type = \"sim\")",
      "sim driver",
      {
          {"kind", ValueType::String, "", "\"circle\"",
           "static, circle, figure_eight, random_walk or waypoints"},
          {"center_m", ValueType::FloatArray, "m", "[0, 0, 1.5]", "centre of the motion", -1e4, 1e4, 3},
          {"radius_m", ValueType::Float, "m", "0.5",
           "circle radius, figure-eight half width, random-walk bound", 0, 1e4},
          {"period_s", ValueType::Float, "s", "4", "duration of one lap (circle, figure_eight)", 0.01, 1e6},
          {"walk_sigma_m", ValueType::Float, "m/sqrt(s)", "0.05", "random-walk position diffusion", 0, 100},
          {"walk_sigma_rad", ValueType::Float, "rad/sqrt(s)", "0.1", "random-walk rotation diffusion", 0, 10},
          {"waypoints_m", ValueType::FloatArray, "m", "", "x y z of each waypoint, flattened; a closed "
           "loop (required for waypoints)", -1e4, 1e4},
          {"speed_mps", ValueType::Float, "m/s", "0.5", "speed along the waypoint loop", 0.001, 1000},
          {"sensor_spacing_m", ValueType::Float, "m", "0.1", "offset between sensors along y", 0, 100},
      }};
  return spec;
}

namespace {
MotionConfig read_motion(TableReader& device) {
  MotionConfig m;
  const toml::table* table = device.table("motion");
  if (!table) return m;
  TableReader r(*table, device.path("motion"), sim_motion_spec(), device.file(), device.errors());
  const std::string kind = r.choice(
      "kind", {"static", "circle", "figure_eight", "random_walk", "waypoints"}, "circle");
  m.kind = kind == "static"         ? MotionKind::Static
           : kind == "figure_eight" ? MotionKind::FigureEight
           : kind == "random_walk"  ? MotionKind::RandomWalk
           : kind == "waypoints"    ? MotionKind::Waypoints
                                    : MotionKind::Circle;
  m.center_m = r.vec3("center_m", m.center_m);
  m.radius_m = r.number("radius_m", m.radius_m);
  m.period_s = r.number("period_s", m.period_s);
  m.walk_sigma_m = r.number("walk_sigma_m", m.walk_sigma_m);
  m.walk_sigma_rad = r.number("walk_sigma_rad", m.walk_sigma_rad);
  m.speed_mps = r.number("speed_mps", m.speed_mps);
  m.sensor_spacing_m = r.number("sensor_spacing_m", m.sensor_spacing_m);
  if (r.has("waypoints_m")) {
    const auto flat = r.numbers("waypoints_m");
    if (flat.size() % 3 != 0 || flat.size() < 6)
      r.error("waypoints_m", fmt::format("needs at least 2 points of 3 numbers each, found {} "
                                         "numbers", flat.size()));
    else
      for (std::size_t i = 0; i < flat.size(); i += 3)
        m.waypoints_m.emplace_back(flat[i], flat[i + 1], flat[i + 2]);
  } else if (m.kind == MotionKind::Waypoints) {
    r.error("waypoints_m", "required when kind = \"waypoints\"");
  }
  return m;
}

}  // namespace

SimConfig read_sim_config(TableReader& r, const std::string& device_name) {
  SimConfig c;
  c.device = device_name;
  c.parent_frame = r.string("parent_frame", c.parent_frame);
  if (r.has("sensors") == r.has("sensor_count")) {
    r.error("sensors", "give exactly one of sensors (names) or sensor_count");
  } else if (r.has("sensors")) {
    c.sensors = r.strings("sensors");
    if (c.sensors.empty()) r.error("sensors", "needs at least one sensor name");
    // As many as sensor_count allows: 100,000 names made a device that could not keep
    // its rate and did not stop within daemon.stop_timeout_s.
    if (c.sensors.size() > static_cast<std::size_t>(kMaxSimSensors))
      r.error("sensors", fmt::format("{} sensors: at most {}", c.sensors.size(), kMaxSimSensors));
    std::set<std::string> names;
    for (const auto& s : c.sensors) {
      if (!is_valid_name(s))
        r.error("sensors", fmt::format("'{}' is not a valid sensor name (1-{} of A-Z a-z 0-9 _ -)",
                                       s, kMaxNameLength));
      else if (!names.insert(s).second)
        r.error("sensors", fmt::format("'{}' is listed twice", s));
    }
  } else {
    const auto n = r.integer("sensor_count", 1);
    for (std::int64_t i = 0; i < n; ++i) c.sensors.push_back(fmt::format("s{}", i));
  }
  c.rate_hz = r.number("rate_hz", c.rate_hz);
  c.covariance = read_covariance(r);
  c.seed = static_cast<std::uint64_t>(r.integer("seed", 1));
  c.dropout_every_s = r.number("dropout_every_s", 0);
  c.dropout_duration_s = r.number("dropout_duration_s", 0);
  if (c.dropout_duration_s > 0 && c.dropout_duration_s >= c.dropout_every_s)
    r.error("dropout_duration_s", "must be shorter than dropout_every_s");
  c.publish_truth = r.boolean("publish_truth", true);
  c.inject_failure_every_s = r.number("inject_failure_every_s", 0);
  c.motion = read_motion(r);
  return c;
}

}  // namespace covtrack::sim
