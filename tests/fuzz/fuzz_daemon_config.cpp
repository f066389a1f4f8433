// covtrackd's TOML config as the daemon reads it at start: every section, every driver's
// keys; devices are never opened, and of the files a config names only those a driver
// reads with its config (a Lenz layout). Relative paths resolve against config/.
#include <variant>

#include "config.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace covtrack;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fuzz::Input input({data, size});
  const auto config = server::parse_config(input.rest_text(), COVTRACK_SOURCE_DIR "/config/fuzz.toml");
  if (!config) {
    FUZZ_CHECK(!config.error().message.empty());
    return 0;
  }
  for (const auto& device : config->devices) {
    // A valid device names a known driver, and the fiducial reader's pointer is set.
    const auto* fiducial = std::get_if<std::shared_ptr<const fiducial::FiducialConfig>>(&device.options);
    FUZZ_CHECK(!device.name.empty() && server::find_driver_type(device.type) && (!fiducial || *fiducial));
  }
  FUZZ_CHECK(config->daemon.heartbeat_hz > 0 && fuzz::finite(config->daemon.heartbeat_hz));
  return 0;
}
