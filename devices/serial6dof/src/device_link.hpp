#pragma once
// The driver's side of the wire during configuration and streaming: writes and reads
// through the serial transport, mirrors bytes to the raw channel when asked, and waits
// in a way a stop request cuts short.
#include <chrono>
#include <cstdint>
#include <span>
#include <stop_token>
#include <string_view>
#include <vector>

#include "covtrack/devices/driver.hpp"
#include "covtrack/devices/driver_clock.hpp"
#include "covtrack/devices/serial/serial_port.hpp"

namespace covtrack::serial6dof {

class DeviceLink {
 public:
  DeviceLink(serial::SerialPort& port, SampleSink& sink, bool publish_raw, std::stop_token stop, DriverClock& clock)
      : port_(port), sink_(sink), publish_raw_(publish_raw), stop_(std::move(stop)), clock_(clock) {}

  Result<void> send(std::string_view bytes);
  // Appends what arrives within `timeout` (0 bytes is not an error) to `out`, and then
  // all that is already waiting.
  Result<std::size_t> read(std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout);
  // The same, waiting at most until `until` on clock().
  Result<std::size_t> read_until(std::vector<std::uint8_t>& out, DriverClock::time_point until);
  // Discards input until none arrived for `quiet` (at most 1 s): stale records, echoes.
  Result<void> drain(std::chrono::milliseconds quiet);
  // Returns false when stop was requested.
  bool sleep(double seconds);
  bool stopped() const { return stop_.stop_requested(); }
  // The driver's clock: every wait above is on it.
  DriverClock& clock() const { return clock_; }
  // now() + seconds, for deadlines on clock().
  DriverClock::time_point after(double seconds) const;
  const std::string& path() const { return port_.path(); }

 private:
  serial::SerialPort& port_;
  SampleSink& sink_;
  bool publish_raw_;
  std::stop_token stop_;
  DriverClock& clock_;
};

}  // namespace covtrack::serial6dof
