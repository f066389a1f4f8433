#pragma once
// Exclusive use of a serial port, taken the way the platform's other serial programs
// (minicom, picocom, gpsd, ModemManager, pppd) take it, so that two programs on one port
// refuse each other instead of resetting each other's device:
//
// - the UUCP lock file <lock_dir>/LCK..<name>, <name> being the device's path under
//   /dev with '/' as '_' (LCK..ttyUSB0, LCK..pts_3), symbolic links resolved first, so
//   /dev/serial/by-id/... and /dev/ttyUSB0 share one lock. It holds the holder's pid as
//   ASCII, "%10d\n". A lock file whose pid is dead (or that holds no pid) is stale and
//   removed. When lock_dir cannot be written (no permission, read-only, missing), the
//   port is locked by flock alone, which is said at debug level;
// - flock(LOCK_EX | LOCK_NB) on a descriptor of the port that the lock keeps open, taken
//   before the port is set up, so a program that uses flock alone is not disturbed.
//
// A refusal names the holder: its pid and, when /proc lets us read it, its name
// (describe_process).
#include <string>

#include "covtrack/protocol/result.hpp"

namespace covtrack::serial {

// $COVTRACK_LOCK_DIR when it is set and not empty (tests; a system whose lock files live
// elsewhere), else /var/lock.
std::string default_lock_dir();

// <lock_dir>/LCK..<name> for the device at `device_path`.
std::string lock_file_path(const std::string& device_path, const std::string& lock_dir);

// Who holds the device's lock file ("covtrackd (pid 1234)"), or empty when there is no
// lock file or its pid is dead.
std::string lock_file_holder(const std::string& device_path, const std::string& lock_dir);

class PortLock {
 public:
  // Takes the lock file before the port is opened (opening a port already toggles its
  // modem lines). Fails naming the holder when a live process holds it.
  static Result<PortLock> acquire(const std::string& device_path, const std::string& lock_dir);

  // Then flock on `fd`, a descriptor of the port that the lock now owns (and closes when
  // it is released). Fails naming the processes that have the device open when another
  // descriptor holds the flock (a program that uses no lock file).
  Result<void> flock_port(int fd);

  PortLock(PortLock&& other) noexcept;
  PortLock& operator=(PortLock&& other) noexcept;
  PortLock(const PortLock&) = delete;
  PortLock& operator=(const PortLock&) = delete;
  // Removes the lock file if it still holds this process's pid, and closes the flocked
  // descriptor.
  ~PortLock();

  // The lock file held, or empty when the lock directory could not be written.
  const std::string& file() const { return file_; }

 private:
  PortLock(std::string device_path, std::string file) : device_path_(std::move(device_path)), file_(std::move(file)) {}
  void release() noexcept;

  std::string device_path_;
  std::string file_;
  int fd_ = -1;  // the flocked descriptor
};

}  // namespace covtrack::serial
