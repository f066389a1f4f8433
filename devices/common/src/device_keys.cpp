#include "covtrack/devices/device_keys.hpp"

namespace covtrack {

std::vector<KeySpec> device_common_keys() {
  return {
      {"type", ValueType::String, "", "", "driver: one of the types listed in this document"},
      {"enabled", ValueType::Boolean, "", "true", "false keeps the table but starts nothing"},
      {"parent_frame", ValueType::String, "", "\"world\"",
       "frame the device reports its sensors' poses in (T_parent_child)"},
  };
}

}  // namespace covtrack
