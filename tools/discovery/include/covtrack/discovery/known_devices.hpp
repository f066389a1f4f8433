#pragma once
// The USB ids covtrack recognises: devices it drives and the USB-serial chips that
// commonly carry them, each with a ready daemon-config snippet. Pure: no I/O.
#include <cstdint>
#include <string>
#include <vector>

namespace covtrack::discovery {

struct KnownDevice {
  std::uint16_t vendor_id;
  std::uint16_t product_id;  // 0: any product of the vendor
  std::string name;          // what it is
  std::string driver_type;   // covtrack's `type`, or empty when it needs a step first
  std::string note;          // what to check or do
};

const std::vector<KnownDevice>& known_devices();

// The best match (an exact product before a vendor-wide row), or nullptr.
const KnownDevice* recognise(std::uint16_t vendor_id, std::uint16_t product_id);

// A [devices.<name>] table for the device at `path` (a tty or HID path; a placeholder
// when empty), with comments for what the user must fill in.
std::string config_snippet(const KnownDevice& device, const std::string& path);

}  // namespace covtrack::discovery
