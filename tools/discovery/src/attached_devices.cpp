#include "covtrack/discovery/attached_devices.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>

#include <fmt/format.h>
#include <hidapi/hidapi.h>
#include <libusb-1.0/libusb.h>

namespace covtrack::discovery {
namespace {

namespace fs = std::filesystem;

std::string read_line(const fs::path& p) {
  std::ifstream in(p);
  std::string s;
  std::getline(in, s);
  return s;
}

std::optional<std::uint16_t> read_hex(const fs::path& p) {
  const std::string s = read_line(p);
  if (s.empty()) return std::nullopt;
  try {
    return static_cast<std::uint16_t>(std::stoul(s, nullptr, 16));
  } catch (...) {
    return std::nullopt;
  }
}

// Walks up from the tty's sysfs device to the USB device that carries it.
void usb_ids_of_tty(const std::string& sys_root, const std::string& tty, SerialPortInfo& info) {
  std::error_code ec;
  fs::path dir = fs::canonical(fs::path(sys_root) / "class/tty" / tty / "device", ec);
  for (int depth = 0; !ec && depth < 6 && dir.has_parent_path(); ++depth, dir = dir.parent_path()) {
    if (fs::exists(dir / "idVendor")) {
      info.vendor_id = read_hex(dir / "idVendor");
      info.product_id = read_hex(dir / "idProduct");
      return;
    }
  }
}

// A ttyS node exists for every possible legacy UART; only a known port type means a
// UART is really there (type 0 is "unknown").
bool legacy_uart_present(const std::string& sys_root, const std::string& tty) {
  const std::string type = read_line(fs::path(sys_root) / "class/tty" / tty / "type");
  return !type.empty() && type != "0";
}

void find_serial(const std::string& dev_root, const std::string& sys_root, AttachedDevices& out) {
  std::error_code ec;
  std::map<std::string, std::string> by_id;  // canonical tty path -> by-id link
  for (const auto& e : fs::directory_iterator(fs::path(dev_root) / "serial/by-id", ec))
    by_id[fs::canonical(e.path(), ec).string()] = e.path().string();
  static const std::regex tty_name(R"(tty(USB|ACM|S)[0-9]+)");
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dev_root, ec)) {
    const std::string name = e.path().filename().string();
    if (std::regex_match(name, tty_name)) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  for (const auto& name : names) {
    if (name.starts_with("ttyS") && !legacy_uart_present(sys_root, name)) continue;
    SerialPortInfo info;
    info.path = (fs::path(dev_root) / name).string();
    if (auto it = by_id.find(fs::weakly_canonical(info.path, ec).string()); it != by_id.end())
      info.by_id = it->second;
    usb_ids_of_tty(sys_root, name, info);
    out.serial.push_back(info);
  }
}

void find_usb(AttachedDevices& out) {
  libusb_context* ctx = nullptr;
  if (const int rc = libusb_init(&ctx); rc != 0) {
    out.problems.push_back(fmt::format("USB: libusb cannot start ({})", libusb_error_name(rc)));
    return;
  }
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx, &list);
  if (n < 0) out.problems.push_back(fmt::format("USB: cannot list devices ({})", libusb_error_name(static_cast<int>(n))));
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
    out.usb.push_back({d.idVendor, d.idProduct, libusb_get_bus_number(list[i]),
                       libusb_get_device_address(list[i])});
  }
  if (n >= 0) libusb_free_device_list(list, 1);
  libusb_exit(ctx);
}

std::string narrow(const wchar_t* w) {
  std::string s;
  for (; w && *w; ++w) s.push_back(*w < 128 ? static_cast<char>(*w) : '?');
  return s;
}

void find_hid(AttachedDevices& out) {
  if (hid_init() != 0) {
    out.problems.push_back("HID: hidapi cannot start");
    return;
  }
  hid_device_info* list = hid_enumerate(0, 0);
  for (auto* d = list; d; d = d->next)
    out.hid.push_back({d->path ? d->path : "", d->vendor_id, d->product_id,
                       narrow(d->product_string), d->interface_number});
  hid_free_enumeration(list);
  hid_exit();
}

}  // namespace

AttachedDevices find_attached_devices(const std::string& dev_root, const std::string& sys_root) {
  AttachedDevices out;
  find_serial(dev_root, sys_root, out);
  find_usb(out);
  find_hid(out);
  return out;
}

}  // namespace covtrack::discovery
