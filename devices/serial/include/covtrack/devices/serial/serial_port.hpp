#pragma once
// A serial port opened by path through libserial, with the failure modes of a device
// that can vanish at any moment turned into Result values instead of exceptions.
//
// Why not call libserial's Read/Close directly: on a device that went away (USB-serial
// adapter unplugged, emulator closed its pseudo-terminal) Read throws with the text
// "Success", and Close throws from the destructor, which terminates the process
// (docs/libserial.md). Reading and writing here go through the raw descriptor with
// poll(), and the teardown is made safe before libserial gets to restore settings. The
// same destructor abort follows opening a path that is not a terminal (a typo naming a
// file), so open() checks the path's kind first.
//
// A port is used by one program at a time: open() takes its lock (port_lock.hpp, the UUCP
// lock file and flock) and fails naming the holder when another program has it.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "covtrack/devices/serial/port_lock.hpp"
#include "covtrack/protocol/result.hpp"

namespace LibSerial {
class SerialPort;
}

namespace covtrack::serial {

struct SerialSettings {
  std::string path;            // e.g. /dev/ttyUSB0, or a symlink to a pseudo-terminal
  int baud = 19200;            // one of the standard rates (see is_supported_baud)
  bool rts_cts = false;        // hardware flow control; 8N1 always
  std::string lock_dir = default_lock_dir();  // where the UUCP lock file goes
};

class SerialPort {
 public:
  // Opens and configures the port (raw 8N1), discarding anything already buffered.
  // Fails with a message naming the path when the device is missing or refuses.
  static Result<std::unique_ptr<SerialPort>> open(const SerialSettings& settings);

  ~SerialPort();
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Reads what is available, waiting at most `timeout` for the first byte. Returns 0
  // bytes on timeout; an error once the device has gone away (hang-up, EOF, EIO).
  Result<std::size_t> read_some(std::span<std::uint8_t> buffer, std::chrono::milliseconds timeout);

  // Appends to `out` what arrives within `timeout`, then everything else already waiting
  // (up to kMostWaiting bytes), and returns how many bytes it appended. Why: a terminal
  // hands out at most 4 KB per read, and after a hold-up (the daemon stalled) the backlog
  // can be larger; a driver that times what it reads by how long it was held up must
  // see the whole backlog in one read, or it times the rest as if it had just arrived.
  // A failure after some bytes keeps them and shows at the next call.
  static constexpr std::size_t kMostWaiting = 64 * 1024;
  Result<std::size_t> read_waiting(std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout);

  // Writes all bytes, waiting at most `timeout` in total for the device to take them.
  Result<void> write_all(std::span<const std::uint8_t> bytes, std::chrono::milliseconds timeout);

  const std::string& path() const { return path_; }
  bool disconnected() const { return disconnected_; }

 private:
  SerialPort(std::unique_ptr<LibSerial::SerialPort> port, std::string path, std::optional<PortLock> lock = {});
  Error disconnect_error(const std::string& what);
  void close_safely() noexcept;

  // Declared first, so destroyed last: the lock file goes once the port is closed.
  std::optional<PortLock> lock_;
  std::unique_ptr<LibSerial::SerialPort> port_;
  std::string path_;
  int fd_ = -1;
  bool disconnected_ = false;
  std::string disconnect_reason_;  // the first, told again by every later call
};

}  // namespace covtrack::serial
