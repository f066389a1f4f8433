#include "covtrack/discovery/known_devices.hpp"

#include <fmt/format.h>

#include "covtrack/devices/hydra/hydra_driver.hpp"
#include "covtrack/devices/lenz/lenz_driver.hpp"
#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"

namespace covtrack::discovery {

const std::vector<KnownDevice>& known_devices() {
  static const std::vector<KnownDevice> table = {
      {lenz::kLiUsbVendorId, lenz::kLiUsbProductId,
       "FTDI FT232 USB-serial (Lenz LI-USB; also common RS-232 adapters)", "lenz",
       "a Lenz LI-USB shows up as this chip; the same chip in a plain adapter may carry a "
       "FASTRAK, IS-900, LIBERTY or Flock (then use type fastrak/liberty/flock)"},
      {0x0403, 0x6015, "FTDI FT-X USB-serial adapter", "fastrak",
       "an RS-232 adapter: set type to the tracker behind it (fastrak, liberty or flock)"},
      {0x0403, 0, "FTDI USB-serial adapter", "fastrak",
       "an RS-232 adapter: set type to the tracker behind it (fastrak, liberty or flock)"},
      {0x067b, 0x2303, "Prolific PL2303 USB-serial adapter", "fastrak",
       "an RS-232 adapter: set type to the tracker behind it (fastrak, liberty or flock)"},
      {serial6dof::kPolhemusVendorId, serial6dof::kLibertyProductId, "Polhemus LIBERTY (USB)",
       "liberty",
       "its USB port needs the usbserial module bound to 0f44:ff20 for a tty; the RS-232 port "
       "works as it is"},
      {serial6dof::kPolhemusVendorId, serial6dof::kLibertyNoFirmwareProductId,
       "Polhemus LIBERTY (USB, firmware not loaded)", "",
       "load its firmware first (fxload, Polhemus' Linux tools); it then re-appears as 0f44:ff20"},
      {serial6dof::kPolhemusVendorId, 0, "Polhemus USB device", "liberty",
       "LIBERTY/PATRIOT speak type liberty, FASTRAK type fastrak; use its serial port"},
      {hydra::kVendorId, hydra::kProductId, "Razer Hydra", "hydra", "two controllers over HID feature reports"},
  };
  return table;
}

const KnownDevice* recognise(std::uint16_t vendor, std::uint16_t product) {
  const KnownDevice* vendor_wide = nullptr;
  for (const auto& d : known_devices()) {
    if (d.vendor_id != vendor) continue;
    if (d.product_id == product) return &d;
    if (d.product_id == 0 && !vendor_wide) vendor_wide = &d;
  }
  return vendor_wide;
}

std::string config_snippet(const KnownDevice& d, const std::string& path) {
  if (d.driver_type.empty()) return fmt::format("# {}: {}\n", d.name, d.note);
  const std::string where = path.empty() ? "/dev/ttyUSB0  # check the path" : path;
  std::string s = fmt::format("# {}\n# {}\n[devices.{}]\ntype = \"{}\"\n", d.name, d.note,
                              d.driver_type, d.driver_type);
  if (d.driver_type == "hydra") {
    if (!path.empty()) s += fmt::format("hid_path = \"{}\"\n", path);
    return s;
  }
  s += fmt::format("port = \"{}\"\n", where);
  if (d.driver_type == "lenz") return s;
  s += "baud = 115200           # as set on the unit\n"
       "[[devices." + d.driver_type + ".stations]]\nnumber = 1\nname = \"st1\"\n";
  return s;
}

}  // namespace covtrack::discovery
