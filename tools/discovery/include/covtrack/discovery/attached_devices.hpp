#pragma once
// What is attached right now: serial ports (/dev/serial/by-id, ttyUSB*, ttyACM*, ttyS*
// with a UART behind them), USB devices (libusb) and HID devices (hidapi). A source that
// cannot be read here (no /dev/bus/usb in a container) says so instead of failing.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace covtrack::discovery {

struct SerialPortInfo {
  std::string path;     // /dev/ttyUSB0 ...
  std::string by_id;    // its /dev/serial/by-id/ name, if any
  std::optional<std::uint16_t> vendor_id, product_id;  // the USB device behind it
};

struct UsbDeviceInfo {
  std::uint16_t vendor_id = 0, product_id = 0;
  int bus = 0, address = 0;
};

struct HidDeviceInfo {
  std::string path;
  std::uint16_t vendor_id = 0, product_id = 0;
  std::string product;
  int interface_number = -1;
};

struct AttachedDevices {
  std::vector<SerialPortInfo> serial;
  std::vector<UsbDeviceInfo> usb;
  std::vector<HidDeviceInfo> hid;
  std::vector<std::string> problems;  // sources that could not be read, and why
};

// `dev_root` and `sys_root` are "/dev" and "/sys" except in tests.
AttachedDevices find_attached_devices(const std::string& dev_root = "/dev",
                                      const std::string& sys_root = "/sys");

}  // namespace covtrack::discovery
