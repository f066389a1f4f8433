#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"

#include <algorithm>
#include <array>
#include <set>

#include <fmt/format.h>

#include "covtrack/devices/covariance_keys.hpp"
#include "covtrack/devices/device_keys.hpp"
#include "covtrack/devices/motion_limit_keys.hpp"
#include "covtrack/devices/serial/baud_rate.hpp"
#include "covtrack/protocol/channels.hpp"
#include "device_model.hpp"

namespace covtrack::serial6dof {
namespace {

std::vector<std::string_view> models_of(Protocol p) {
  switch (p) {
    case Protocol::Fastrak: return {"fastrak", "is900"};
    case Protocol::Liberty: return {"liberty", "patriot"};
    case Protocol::Flock: return {"flock"};
  }
  return {};
}

Model model_named(const std::string& name) {
  for (Model m : {Model::Fastrak, Model::Is900, Model::Liberty, Model::Patriot, Model::Flock})
    if (model_spec(m).name == name) return m;
  return Model::Fastrak;
}

TableSpec make_device_spec(Protocol p) {
  static const std::array<std::string, 3> names = {
      "devices.<name> (type = \"fastrak\")", "devices.<name> (type = \"liberty\")",
      "devices.<name> (type = \"flock\")"};
  static const std::array<std::string, 3> models = {"\"fastrak\"", "\"liberty\"", "\"flock\""};
  const auto i = static_cast<std::size_t>(p);
  TableSpec s{names[i], "serial 6-DOF driver", device_common_keys()};
  std::vector<KeySpec> own = {
      {"port", ValueType::String, "", "", "serial device, e.g. /dev/ttyUSB0 or a /dev/serial/by-id/ path"},
      {"baud", ValueType::Integer, "baud", "115200", "serial rate, as set on the unit"},
      {"model", ValueType::String, "", models[i],
       p == Protocol::Fastrak   ? "fastrak or is900 (IS-900 in Fastrak mode): sets the defaults"
       : p == Protocol::Liberty ? "liberty or patriot: sets the defaults"
                                : "flock"},
      {"stations", ValueType::TableArray, "", "one, number 1",
       "the receivers to use: see devices.<name>.stations"},
      {"rate_hz", ValueType::Float, "Hz", "the model's",
       "expected reports per second per station (Fastrak: 120 shared by the stations)", 0.1, 10000},
      {"watchdog_periods", ValueType::Float, "", "1.5",
       "a station is reported LOST after this many report periods without a record (1.5: "
       "LOST within 2 periods; raise it for a fast unit on a loaded machine)", 1, 1000},
      {"reset_on_start", ValueType::Boolean, "", "true",
       "reset the unit before configuring it (restarts after a failure always reset)"},
      {"reset_time_s", ValueType::Float, "s", "the model's",
       "how long a reset takes (Fastrak 10, IS-900 20, Liberty 5, Flock 10)", 0, 120},
      {"reply_timeout_s", ValueType::Float, "s", "1", "longest wait for a status or setting reply", 0.01, 60},
      {"trouble_inflation", ValueType::Float, "", "10",
       "covariance factor for a record the unit flags (status letter, error code, out of range)", 1, 1e6},
      {"latency_s", ValueType::Float, "s", "the model's",
       "subtracted from the receive time to get the measurement time", 0, 1},
      {"publish_raw", ValueType::Boolean, "", "false", "publish the bytes read on covtrack/raw/<device>"},
  };
  if (p == Protocol::Fastrak || p == Protocol::Liberty)
    own.push_back({"units", ValueType::String, "", "\"cm\"",
                   "cm or inches: set on the unit and confirmed before streaming"});
  if (p == Protocol::Fastrak)
    own.push_back({"output_items", ValueType::StringArray, "", "[]",
                   "after position and quaternion: timestamp, buttons, joystick (IS-900), stylus (Fastrak)"});
  if (p == Protocol::Liberty)
    own.push_back({"output_items", ValueType::StringArray, "", "[]",
                   "after position and quaternion: timestamp, frame_count, stylus"});
  if (p == Protocol::Flock)
    own.push_back({"position_scale_in", ValueType::Float, "in", "36",
                   "full scale: 36 or 72 (standard transmitter), 144 (extended range); confirmed "
                   "against the unit", 36, 144});
  for (const auto& k : motion_limit_keys()) own.push_back(k);
  const auto cov = covariance_keys();
  for (auto k : cov) {
    k.default_value = "the model's";  // optional here: the static accuracy of protocols B.4
    own.push_back(k);
  }
  s.keys.insert(s.keys.end(), own.begin(), own.end());
  return s;
}

TableSpec make_station_spec(Protocol p) {
  static const std::array<std::string, 3> names = {
      "devices.<name>.stations (type = \"fastrak\")", "devices.<name>.stations (type = \"liberty\")",
      "devices.<name>.stations (type = \"flock\")"};
  TableSpec s{names[static_cast<std::size_t>(p)], "serial 6-DOF driver",
              {{"number", ValueType::Integer, "", "",
                p == Protocol::Flock ? "the bird's FBB address" : "the receiver's station number",
                1, p == Protocol::Fastrak ? 12.0 : p == Protocol::Liberty ? 16.0 : 30.0},
               {"name", ValueType::String, "", "\"st<number>\"", "sensor name (child frame)"}}};
  for (auto k : covariance_keys()) {
    k.default_value = "the device's";
    s.keys.push_back(k);
  }
  return s;
}

template <typename Extra>
std::vector<Extra> read_extras(TableReader& r, const std::vector<std::pair<std::string_view, Extra>>& known) {
  std::vector<Extra> out;
  if (!r.has("output_items")) return out;
  for (const auto& item : r.strings("output_items")) {
    auto it = std::find_if(known.begin(), known.end(), [&](auto& k) { return k.first == item; });
    if (it == known.end()) {
      std::string names;
      for (auto& k : known) names += std::string(names.empty() ? "" : ", ") + std::string(k.first);
      r.error("output_items", fmt::format("'{}' is not one of {}", item, names));
    } else {
      out.push_back(it->second);
    }
  }
  return out;
}

bool has_covariance(TableReader& r) {
  return r.has("covariance") || r.has("sigma_m") || r.has("sigma_rad");
}

}  // namespace

const TableSpec& serial6dof_device_spec(Protocol p) {
  static const std::array<TableSpec, 3> specs = {make_device_spec(Protocol::Fastrak),
                                                 make_device_spec(Protocol::Liberty),
                                                 make_device_spec(Protocol::Flock)};
  return specs[static_cast<std::size_t>(p)];
}

const TableSpec& serial6dof_station_spec(Protocol p) {
  static const std::array<TableSpec, 3> specs = {make_station_spec(Protocol::Fastrak),
                                                 make_station_spec(Protocol::Liberty),
                                                 make_station_spec(Protocol::Flock)};
  return specs[static_cast<std::size_t>(p)];
}

Serial6dofConfig read_serial6dof_config(TableReader& r, const std::string& device_name,
                                        Protocol protocol) {
  Serial6dofConfig c;
  c.device = device_name;
  c.parent_frame = r.string("parent_frame", c.parent_frame);
  const auto allowed = models_of(protocol);
  c.model = model_named(r.choice("model", allowed, std::string(allowed.front())));
  const ModelSpec& spec = model_spec(c.model);
  c.port = r.string("port");
  c.baud = static_cast<int>(r.integer("baud", c.baud));
  if (r.has("baud") && !serial::is_supported_baud(c.baud))
    r.error("baud", fmt::format("{} is not a standard serial rate", c.baud));

  std::optional<Mat6> device_cov;
  if (has_covariance(r)) device_cov = read_covariance(r);
  // One error per repeated station, not one per pair: a config repeating a station
  // thousands of times is reported in linear time and memory.
  std::set<int> numbers;
  std::set<std::string> names;
  for (const toml::table* t : r.tables("stations")) {
    const std::string path = r.path("stations") + fmt::format("[{}]", c.stations.size());
    TableReader s(*t, path, serial6dof_station_spec(protocol), r.file(), r.errors());
    StationConfig st;
    st.number = static_cast<int>(s.integer("number", 1));
    st.name = s.string("name", fmt::format("st{}", st.number));
    if (!is_valid_name(st.name))
      s.error("name", fmt::format("'{}' is not a valid sensor name (1-{} of A-Z a-z 0-9 _ -)",
                                  st.name, kMaxNameLength));
    st.covariance = has_covariance(s) ? std::optional<Mat6>(read_covariance(s)) : device_cov;
    if (!numbers.insert(st.number).second) s.error("number", fmt::format("station {} is listed twice", st.number));
    if (!names.insert(st.name).second) s.error("name", fmt::format("sensor name '{}' is used twice", st.name));
    c.stations.push_back(st);
  }
  if (c.stations.empty()) c.stations.push_back({1, "st1", device_cov});

  if (protocol != Protocol::Flock)
    c.units = r.choice("units", {"cm", "inches"}, "cm") == "inches" ? Units::Inches : Units::Centimetres;
  if (protocol == Protocol::Fastrak) {
    c.fastrak_extras = read_extras<FastrakExtra>(
        r, {{"timestamp", FastrakExtra::Timestamp}, {"buttons", FastrakExtra::Buttons},
            {"stylus", FastrakExtra::Stylus}, {"joystick", FastrakExtra::Joystick}});
    const bool is900_only = std::any_of(c.fastrak_extras.begin(), c.fastrak_extras.end(), [](auto e) {
      return e != FastrakExtra::Stylus;
    });
    if (is900_only && c.model != Model::Is900)
      r.error("output_items", "timestamp, buttons and joystick need model = \"is900\"");
  }
  if (protocol == Protocol::Liberty)
    c.liberty_extras = read_extras<LibertyExtra>(
        r, {{"timestamp", LibertyExtra::Timestamp}, {"frame_count", LibertyExtra::FrameCount},
            {"stylus", LibertyExtra::Stylus}});
  if (protocol == Protocol::Flock) {
    c.flock_position_scale_in = r.number("position_scale_in", 36);
    if (c.flock_position_scale_in != 36 && c.flock_position_scale_in != 72 &&
        c.flock_position_scale_in != 144)
      r.error("position_scale_in", "must be 36, 72 or 144");
  }

  c.rate_hz = r.number("rate_hz", station_rate_hz(spec, static_cast<int>(c.stations.size())));
  c.watchdog_periods = r.number("watchdog_periods", c.watchdog_periods);
  c.reset_on_start = r.boolean("reset_on_start", true);
  c.reset_time_s = r.number("reset_time_s", spec.reset_time_s);
  c.reply_timeout_s = r.number("reply_timeout_s", c.reply_timeout_s);
  c.trouble_inflation = r.number("trouble_inflation", c.trouble_inflation);
  c.latency_s = r.number("latency_s", spec.latency_s);
  c.publish_raw = r.boolean("publish_raw", false);
  c.motion = read_motion_limits(r);
  return c;
}

}  // namespace covtrack::serial6dof
