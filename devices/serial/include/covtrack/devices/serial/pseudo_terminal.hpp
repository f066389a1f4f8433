#pragma once
// The device side of a pseudo-terminal, for emulators and tests: it owns the master,
// and a driver opens the slave as if it were a serial device.
//
// A stable device path: the slave's /dev/pts/N name changes each time a pseudo-terminal
// is created, so the helper can keep a symbolic link (the path a driver config names)
// pointing at the current slave. unplug() closes the master and removes the link, as a
// USB-serial adapter's /dev node disappears; replug() creates a new pseudo-terminal and
// points the link at it again.
//
// Not thread-safe: one thread (the emulator's) calls everything.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "covtrack/protocol/result.hpp"

namespace covtrack::serial {

class PseudoTerminal {
 public:
  // link_path empty: no link; device_path() is then the slave itself.
  static Result<PseudoTerminal> create(std::string link_path = {});

  PseudoTerminal(PseudoTerminal&& other) noexcept;
  PseudoTerminal& operator=(PseudoTerminal&& other) noexcept;
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;
  ~PseudoTerminal();

  // The path a driver should open: the link if there is one, else the slave.
  const std::string& device_path() const { return link_path_.empty() ? slave_path_ : link_path_; }
  const std::string& slave_path() const { return slave_path_; }
  bool plugged() const { return master_ >= 0; }

  void unplug();
  Result<void> replug();

  // Bytes the driver wrote; waits at most `timeout`. 0 bytes on timeout, and also while
  // no driver has the slave open (the master then reports a hang-up, which is normal for
  // a device whose host has not connected yet). Error only when unplugged.
  Result<std::size_t> read_some(std::span<std::uint8_t> buffer, std::chrono::milliseconds timeout);

  // Sends bytes towards the driver. Like a real device, what the other side does not
  // take (buffer full, nobody listening) is dropped; returns how many bytes went out.
  Result<std::size_t> write(std::span<const std::uint8_t> bytes);

 private:
  PseudoTerminal() = default;
  Result<void> open_master();

  int master_ = -1;
  std::string slave_path_;
  std::string link_path_;
};

}  // namespace covtrack::serial
