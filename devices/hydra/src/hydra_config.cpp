#include <numbers>

#include <fmt/format.h>

#include "covtrack/devices/covariance_keys.hpp"
#include "covtrack/devices/device_keys.hpp"
#include "covtrack/devices/motion_limit_keys.hpp"
#include "covtrack/devices/valid_frame_watchdog.hpp"
#include "covtrack/devices/hydra/hydra_driver.hpp"
#include "covtrack/protocol/channels.hpp"

namespace covtrack::hydra {

Mat6 hydra_default_covariance() {
  constexpr double sigma_m = 1e-3, sigma_rad = std::numbers::pi / 180.0;
  Mat6 c = Mat6::Zero();
  c.diagonal() << Vec3::Constant(sigma_m * sigma_m), Vec3::Constant(sigma_rad * sigma_rad);
  return c;
}

const TableSpec& hydra_device_spec() {
  static const TableSpec spec = [] {
    TableSpec s{"devices.<name> (type = \"hydra\")", "Razer Hydra driver", device_common_keys()};
    const std::vector<KeySpec> own = {
        {"hid_path", ValueType::String, "", "the first Hydra found",
         "hidapi path of the data interface (covtrack devices lists it)"},
        {"sensors", ValueType::StringArray, "", "[\"left\", \"right\"]", "names of the two controllers"},
        {"rate_hz", ValueType::Float, "Hz", "250", "expected reports per second", 1, 10000},
        {"watchdog_periods", ValueType::Float, "", "4",
         "controllers are reported LOST after this many periods without a report", 1, 1000},
        no_valid_frames_key("10", "no motion report that parses for this long, whatever the base sends: "
                            "the device FAILED and restarted (\"no valid frames for N s\"); the motion-mode "
                            "switch is repeated every 2 s meanwhile"),
    };
    s.keys.insert(s.keys.end(), own.begin(), own.end());
    for (const auto& k : motion_limit_keys()) s.keys.push_back(k);
    for (auto k : covariance_keys()) {
      k.default_value = "1 mm, 1 degree";
      s.keys.push_back(k);
    }
    return s;
  }();
  return spec;
}

HydraConfig read_hydra_config(TableReader& r, const std::string& name) {
  HydraConfig c;
  c.device = name;
  c.parent_frame = r.string("parent_frame", c.parent_frame);
  c.hid_path = r.string("hid_path", "");
  if (r.has("sensors")) {
    const auto s = r.strings("sensors");
    if (s.size() != 2) r.error("sensors", fmt::format("needs exactly 2 names, found {}", s.size()));
    else c.sensors = {s[0], s[1]};
    for (const auto& n : s)
      if (!is_valid_name(n)) r.error("sensors", fmt::format("'{}' is not a valid sensor name", n));
  }
  c.rate_hz = r.number("rate_hz", c.rate_hz);
  c.watchdog_periods = r.number("watchdog_periods", c.watchdog_periods);
  c.no_valid_frames_s = r.number(kNoValidFramesKey, c.no_valid_frames_s);
  const bool given = r.has("covariance") || r.has("sigma_m") || r.has("sigma_rad");
  c.covariance = given ? read_covariance(r) : hydra_default_covariance();
  c.motion = read_motion_limits(r);
  return c;
}

}  // namespace covtrack::hydra
