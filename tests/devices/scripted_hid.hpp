#pragma once
// A hidraw node whose reports the test writes, for the Hydra driver's read loop.
//
// This machine has no hidraw device and no /dev/uhid to make one, so hidapi cannot be
// run against a device here. scripted_hid.cpp defines the hidapi functions the driver
// calls (hid_init, hid_open_path, hid_read_timeout, hid_send_feature_report, hid_close);
// an executable's own definitions take the place of the shared library's, so a test
// linked with it drives the driver's unchanged code over this device. It opens at
// kPath, a character device, as the driver requires of a hidraw node.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <span>
#include <vector>

namespace covtrack::test {

class ScriptedHid {
 public:
  static constexpr const char* kPath = "/dev/null";

  // Back to a device with nothing queued, never opened, plugged in.
  void reset();
  // A report waiting in the kernel's queue; reads take them in order.
  void queue(std::span<const std::uint8_t> report);
  // Reads fail from now on, as when the device is unplugged. (hidapi's hidraw reader
  // checks the descriptor for a hang-up before it reads, so reports still queued in the
  // kernel are not read either.)
  void unplug();
  // The device is unplugged after `reads` more reports have been read: the reader takes
  // them, then fails, as when the base goes in the middle of a backlog.
  void unplug_after(int reads);

  std::size_t waiting() const;
  int feature_reports() const;  // received (the motion-mode switch)
  bool open() const;

  // For scripted_hid.cpp's hidapi functions.
  bool take_open();
  void close();
  int read(std::uint8_t* data, std::size_t length);
  void feature_report();

 private:
  mutable std::mutex m_;
  std::deque<std::vector<std::uint8_t>> queue_;
  bool open_ = false, unplugged_ = false;
  int reads_until_unplugged_ = -1;  // -1: no unplug due
  int feature_reports_ = 0;
};

// The one device hidapi's functions reach.
ScriptedHid& scripted_hid();

}  // namespace covtrack::test
