#include "covtrack/devices/serial/serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <vector>
#include <libserial/SerialPort.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "covtrack/devices/serial/baud_rate.hpp"
#include "covtrack/devices/serial/device_holders.hpp"

namespace covtrack::serial {
namespace {

LibSerial::BaudRate to_libserial(int baud) {
  switch (baud) {
    case 1200: return LibSerial::BaudRate::BAUD_1200;
    case 2400: return LibSerial::BaudRate::BAUD_2400;
    case 4800: return LibSerial::BaudRate::BAUD_4800;
    case 9600: return LibSerial::BaudRate::BAUD_9600;
    case 19200: return LibSerial::BaudRate::BAUD_19200;
    case 38400: return LibSerial::BaudRate::BAUD_38400;
    case 57600: return LibSerial::BaudRate::BAUD_57600;
    case 115200: return LibSerial::BaudRate::BAUD_115200;
    case 230400: return LibSerial::BaudRate::BAUD_230400;
    case 460800: return LibSerial::BaudRate::BAUD_460800;
    case 921600: return LibSerial::BaudRate::BAUD_921600;
    default: return LibSerial::BaudRate::BAUD_INVALID;
  }
}

// Raw bytes, no waiting inside read(): timeouts come from poll(), so a driver's loop
// keeps control and notices a stop request quickly.
Result<void> make_raw_nonblocking(int fd) {
  termios t{};
  if (::tcgetattr(fd, &t) != 0) return fail(std::strerror(errno));
  const tcflag_t hardware_flow = t.c_cflag & CRTSCTS;
  ::cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD | hardware_flow;
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (::tcsetattr(fd, TCSANOW, &t) != 0) return fail(std::strerror(errno));
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) != 0) return fail(std::strerror(errno));
  ::tcflush(fd, TCIOFLUSH);
  return {};
}

// A regular file, a directory or a missing path is told apart before libserial gets it:
// libserial 1.0.0 opens anything, and on a file that is not a terminal it throws from its
// destructor, which would terminate the daemon over a typo in a config.
Result<void> check_device_kind(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return fail(fmt::format("no such device ({})", std::strerror(errno)));
  if (S_ISCHR(st.st_mode)) return {};
  if (S_ISDIR(st.st_mode)) return fail("is a directory, not a serial device");
  if (S_ISREG(st.st_mode)) return fail("is a regular file, not a serial device");
  return fail("is not a character device, so not a serial device");
}

int open_plain(const std::string& path) { return ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC); }

// Why open() failed with `error`, with what to do about it.
std::string open_error_text(const std::string& path, int error) {
  const std::string text = std::strerror(error);
  if (error == EBUSY) {
    const std::vector<std::string> holders = processes_holding(path);
    if (holders.empty()) return text + " (another program holds it exclusively)";
    return fmt::format("{} (held exclusively; open in: {})", text, fmt::join(holders, ", "));
  }
  if (error == EACCES) return text + " (add the user to the 'dialout' group?)";
  return text;
}

// libserial 1.0.0 calls close(-1) before formatting errno, so its message for every failed
// open is "Bad file descriptor". Repeat the open (it just failed, so it fails again the
// same way, almost always) to report the real errno.
std::string open_failure_reason(const std::string& path) {
  const int fd = open_plain(path);
  if (fd >= 0) {
    ::close(fd);
    return "refused once, then opened (device busy or being re-plugged?)";
  }
  return open_error_text(path, errno);
}

}  // namespace

SerialPort::SerialPort(std::unique_ptr<LibSerial::SerialPort> port, std::string path, std::optional<PortLock> lock)
    : lock_(std::move(lock)), port_(std::move(port)), path_(std::move(path)), fd_(port_->GetFileDescriptor()) {}

SerialPort::~SerialPort() { close_safely(); }

Result<std::unique_ptr<SerialPort>> SerialPort::open(const SerialSettings& settings) {
  const auto where = [&](const std::string& what) { return fmt::format("serial port {}: {}", settings.path, what); };
  if (!is_supported_baud(settings.baud))
    return fail(where(fmt::format("unsupported baud rate {}", settings.baud)));
  if (auto kind = check_device_kind(settings.path); !kind) return fail(where(kind.error().message));
  // Before the open: opening a port already toggles its modem lines, which resets some units.
  auto lock = PortLock::acquire(settings.path, settings.lock_dir);
  if (!lock) return fail(where(lock.error().message));
  const int lock_fd = open_plain(settings.path);
  if (lock_fd < 0) return fail(where(fmt::format("cannot open: {}", open_error_text(settings.path, errno))));
  if (auto locked = lock->flock_port(lock_fd); !locked) return fail(where(locked.error().message));

  auto lib_port = std::make_unique<LibSerial::SerialPort>();
  try {
    lib_port->Open(settings.path);
  } catch (const std::exception& e) {
    if (lib_port->IsOpen()) {
      // The descriptor opened but is not a terminal (tcgetattr failed): libserial would
      // throw again from its destructor. Hand it to the safe teardown instead.
      SerialPort doomed(std::move(lib_port), settings.path);
      doomed.disconnected_ = true;
      return fail(where(fmt::format("opened but cannot be set up as a terminal: {}", e.what())));
    }
    return fail(where(fmt::format("cannot open: {}", open_failure_reason(settings.path))));
  }
  // From here on the wrapper owns the port, so every failure path tears down safely.
  std::unique_ptr<SerialPort> port(new SerialPort(std::move(lib_port), settings.path, std::move(*lock)));
  try {
    port->port_->SetBaudRate(to_libserial(settings.baud));
    port->port_->SetCharacterSize(LibSerial::CharacterSize::CHAR_SIZE_8);
    port->port_->SetParity(LibSerial::Parity::PARITY_NONE);
    port->port_->SetStopBits(LibSerial::StopBits::STOP_BITS_1);
    port->port_->SetFlowControl(settings.rts_cts ? LibSerial::FlowControl::FLOW_CONTROL_HARDWARE
                                                 : LibSerial::FlowControl::FLOW_CONTROL_NONE);
  } catch (const std::exception& e) {
    port->disconnected_ = true;  // state unknown: take the safe teardown
    return fail(where(fmt::format("cannot configure 8N1 at {} baud: {}", settings.baud, e.what())));
  }
  if (auto raw = make_raw_nonblocking(port->fd_); !raw) {
    port->disconnected_ = true;
    return fail(where("cannot set raw mode: " + raw.error().message));
  }
  return port;
}

Error SerialPort::disconnect_error(const std::string& what) {
  disconnected_ = true;
  if (disconnect_reason_.empty()) disconnect_reason_ = what;
  return Error{fmt::format("serial port {}: device disconnected ({})", path_, disconnect_reason_)};
}

Result<std::size_t> SerialPort::read_some(std::span<std::uint8_t> buffer, std::chrono::milliseconds timeout) {
  if (disconnected_) return std::unexpected(disconnect_error("earlier"));
  pollfd p{fd_, POLLIN, 0};
  const int ready = ::poll(&p, 1, static_cast<int>(timeout.count()));
  if (ready < 0) {
    if (errno == EINTR) return 0;
    return std::unexpected(disconnect_error(fmt::format("poll: {}", std::strerror(errno))));
  }
  if (ready == 0) return 0;
  // Read before looking at POLLHUP: the last bytes a device sent may still be buffered.
  if (p.revents & POLLIN) {
    const ssize_t n = ::read(fd_, buffer.data(), buffer.size());
    if (n > 0) return static_cast<std::size_t>(n);
    if (n == 0) return std::unexpected(disconnect_error("end of file"));
    if (errno == EAGAIN || errno == EINTR) return 0;
    return std::unexpected(disconnect_error(std::strerror(errno)));
  }
  if (p.revents & POLLHUP) return std::unexpected(disconnect_error("hang-up"));
  if (p.revents & (POLLERR | POLLNVAL)) return std::unexpected(disconnect_error("error on descriptor"));
  return 0;
}

Result<std::size_t> SerialPort::read_waiting(std::vector<std::uint8_t>& out, std::chrono::milliseconds timeout) {
  std::uint8_t buffer[4096];
  std::size_t total = 0;
  while (total < kMostWaiting) {
    auto n = read_some({buffer, std::min(sizeof buffer, kMostWaiting - total)}, total ? std::chrono::milliseconds(0) : timeout);
    if (!n && total == 0) return n;
    if (!n || *n == 0) break;
    out.insert(out.end(), buffer, buffer + *n);
    total += *n;
  }
  return total;
}

Result<void> SerialPort::write_all(std::span<const std::uint8_t> bytes, std::chrono::milliseconds timeout) {
  if (disconnected_) return std::unexpected(disconnect_error("earlier"));
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::size_t done = 0;
  while (done < bytes.size()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() < 0)
      return fail(fmt::format("serial port {}: write timed out after {} of {} bytes (flow control holding?)", path_,
                              done, bytes.size()));
    pollfd p{fd_, POLLOUT, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno != EINTR) return std::unexpected(disconnect_error(std::strerror(errno)));
    if (ready <= 0) continue;
    if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) return std::unexpected(disconnect_error("hang-up"));
    const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && errno != EAGAIN && errno != EINTR) {
      return std::unexpected(disconnect_error(std::strerror(errno)));
    }
  }
  return {};
}

// libserial's Close restores the old terminal settings first; on a dead device that
// fails, the port stays marked open, and its destructor throws again -> std::terminate.
// So a dead descriptor is swapped for a healthy spare pseudo-terminal slave first.
void SerialPort::close_safely() noexcept {
  if (!port_) return;
  // libserial opens with TIOCEXCL. A pseudo-terminal keeps that flag while its master
  // stays open, so without clearing it the next open of the same emulator (a driver
  // restart) fails with EBUSY for anyone but the real root.
  ::ioctl(fd_, TIOCNXCL);
  if (!disconnected_) {
    try {
      port_->Close();
      port_.reset();
      return;
    } catch (const std::exception&) {
      // fall through to the dead-device path
    }
  }
  int spare_master = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (spare_master >= 0 && ::grantpt(spare_master) == 0 && ::unlockpt(spare_master) == 0) {
    char name[128];
    if (::ptsname_r(spare_master, name, sizeof name) == 0) {
      const int spare_slave = ::open(name, O_RDWR | O_NOCTTY);
      if (spare_slave >= 0) {
        ::dup2(spare_slave, fd_);
        ::close(spare_slave);
      }
    }
  }
  try {
    port_->Close();
    port_.reset();
  } catch (const std::exception&) {
    // Still refused: leaking the small libserial object is better than terminating.
    (void)port_.release();
    ::close(fd_);
  }
  if (spare_master >= 0) ::close(spare_master);
}

}  // namespace covtrack::serial
