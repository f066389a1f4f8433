// `covtrack devices`: what is attached (serial ports, USB, HID), which of it covtrack
// supports or commonly carries a supported tracker, and a config snippet for each; a
// serial port in use says by whom.
#include <algorithm>
#include <memory>

#include <fmt/format.h>

#include "commands.hpp"
#include "covtrack/discovery/attached_devices.hpp"
#include "covtrack/devices/serial/device_holders.hpp"
#include "covtrack/devices/serial/port_lock.hpp"
#include "covtrack/discovery/known_devices.hpp"

namespace covtrack::cli {
namespace {

using namespace covtrack::discovery;

// "  [in use by covtrackd (pid 1234)]": the port's lock file, else the processes that have
// it open (read from /proc, without opening the port: an open can reset a unit).
std::string held_by(const std::string& port) {
  std::string holder = serial::lock_file_holder(port, serial::default_lock_dir());
  if (holder.empty()) {
    for (const auto& p : serial::processes_holding(port)) holder += (holder.empty() ? "" : ", ") + p;
  }
  return holder.empty() ? "" : "  [in use by " + holder + "]";
}

std::string ids(std::uint16_t vendor, std::uint16_t product) {
  return fmt::format("{:04x}:{:04x}", vendor, product);
}

int run_devices(bool snippets) {
  const AttachedDevices found = find_attached_devices();
  std::vector<std::string> configs;

  fmt::print("Serial ports:\n");
  if (found.serial.empty()) fmt::print("  none\n");
  for (const auto& s : found.serial) {
    const std::string path = s.by_id.empty() ? s.path : s.by_id;
    const KnownDevice* known = s.vendor_id ? recognise(*s.vendor_id, *s.product_id) : nullptr;
    fmt::print("  {}{}{}{}\n", path, s.vendor_id ? "  (USB " + ids(*s.vendor_id, *s.product_id) + ")" : "",
               known ? "  -> " + known->name : "", held_by(s.path));
    if (known) configs.push_back(config_snippet(*known, path));
  }

  fmt::print("USB devices:\n");
  if (found.usb.empty()) fmt::print("  none\n");
  for (const auto& u : found.usb) {
    const KnownDevice* known = recognise(u.vendor_id, u.product_id);
    fmt::print("  bus {:03d} device {:03d}  {}{}\n", u.bus, u.address, ids(u.vendor_id, u.product_id),
               known ? "  -> " + known->name : "");
    // Serial adapters get their snippet from the port listing, which knows the path.
    const bool has_tty = std::any_of(found.serial.begin(), found.serial.end(), [&](const auto& s) {
      return s.vendor_id == u.vendor_id && s.product_id == u.product_id;
    });
    if (known && !has_tty && known->driver_type != "hydra") configs.push_back(config_snippet(*known, ""));
  }

  fmt::print("HID devices:\n");
  if (found.hid.empty()) fmt::print("  none\n");
  for (const auto& h : found.hid) {
    const KnownDevice* known = recognise(h.vendor_id, h.product_id);
    fmt::print("  {}  {}  {}{}\n", h.path, ids(h.vendor_id, h.product_id), h.product,
               known ? "  -> " + known->name : "");
    if (known) configs.push_back(config_snippet(*known, h.path));
  }
  for (const auto& p : found.problems) fmt::print("note: {}\n", p);

  if (configs.empty()) {
    fmt::print("\nNothing covtrack supports is attached. Without hardware, try the emulators:\n"
               "  covtrack emulate-6dof --protocol fastrak --link /tmp/fastrak\n");
    return 0;
  }
  if (snippets) {
    fmt::print("\nConfig snippets for covtrackd (see config/schema.md for every key):\n");
    for (const auto& c : configs) fmt::print("\n{}", c);
  }
  return 0;
}

}  // namespace

void add_devices_command(CLI::App& app) {
  auto no_snippets = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("devices", "List attached serial, USB and HID devices and "
                                 "print config snippets for the supported ones");
  cmd->add_flag("--no-snippets", *no_snippets, "only the lists");
  cmd->callback([no_snippets] {
    if (const int rc = run_devices(!*no_snippets); rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace covtrack::cli
