#include "covtrack/devices/serial/pseudo_terminal.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <utility>

#include <fmt/format.h>

namespace covtrack::serial {

Result<PseudoTerminal> PseudoTerminal::create(std::string link_path) {
  PseudoTerminal pty;
  pty.link_path_ = std::move(link_path);
  if (auto opened = pty.open_master(); !opened) return std::unexpected(opened.error());
  return pty;
}

PseudoTerminal::PseudoTerminal(PseudoTerminal&& other) noexcept
    : master_(std::exchange(other.master_, -1)),
      slave_path_(std::move(other.slave_path_)),
      link_path_(std::exchange(other.link_path_, {})) {}

PseudoTerminal& PseudoTerminal::operator=(PseudoTerminal&& other) noexcept {
  if (this != &other) {
    unplug();
    master_ = std::exchange(other.master_, -1);
    slave_path_ = std::move(other.slave_path_);
    link_path_ = std::exchange(other.link_path_, {});
  }
  return *this;
}

PseudoTerminal::~PseudoTerminal() { unplug(); }

Result<void> PseudoTerminal::open_master() {
  // O_CLOEXEC: a child process (a daemon started by a test after the emulator) must not
  // inherit the master, or closing it here would never hang up the driver's side.
  const int fd = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return fail(fmt::format("pseudo-terminal: posix_openpt: {}", std::strerror(errno)));
  char name[128];
  if (::grantpt(fd) != 0 || ::unlockpt(fd) != 0 || ::ptsname_r(fd, name, sizeof name) != 0) {
    const int err = errno;
    ::close(fd);
    return fail(fmt::format("pseudo-terminal: grantpt/unlockpt/ptsname: {}", std::strerror(err)));
  }
  // Raw mode on the pair (Linux applies the master's termios calls to the slave): no echo,
  // no line editing, no CR/LF translation; every byte passes as it is.
  termios t{};
  if (::tcgetattr(fd, &t) == 0) {
    ::cfmakeraw(&t);
    ::tcsetattr(fd, TCSANOW, &t);
  }
  if (!link_path_.empty()) {
    // Replace the link atomically, so a driver never sees a half-made path.
    const std::string tmp = link_path_ + ".tmp";
    ::unlink(tmp.c_str());
    if (::symlink(name, tmp.c_str()) != 0 || ::rename(tmp.c_str(), link_path_.c_str()) != 0) {
      const int err = errno;
      ::close(fd);
      return fail(fmt::format("pseudo-terminal: cannot link {} -> {}: {}", link_path_, name, std::strerror(err)));
    }
  }
  master_ = fd;
  slave_path_ = name;
  return {};
}

void PseudoTerminal::unplug() {
  if (master_ < 0) return;
  if (!link_path_.empty()) ::unlink(link_path_.c_str());
  ::close(master_);
  master_ = -1;
}

Result<void> PseudoTerminal::replug() {
  unplug();
  return open_master();
}

Result<std::size_t> PseudoTerminal::read_some(std::span<std::uint8_t> buffer, std::chrono::milliseconds timeout) {
  if (master_ < 0) return fail("pseudo-terminal: unplugged");
  pollfd p{master_, POLLIN, 0};
  const int ready = ::poll(&p, 1, static_cast<int>(timeout.count()));
  if (ready <= 0) return 0;
  if (p.revents & POLLIN) {
    const ssize_t n = ::read(master_, buffer.data(), buffer.size());
    if (n > 0) return static_cast<std::size_t>(n);
  }
  // Hang-up: no slave open right now. poll() returns at once in that state, so wait out
  // the timeout here instead of letting the caller spin.
  if (p.revents & (POLLHUP | POLLERR)) std::this_thread::sleep_for(timeout);
  return 0;
}

Result<std::size_t> PseudoTerminal::write(std::span<const std::uint8_t> bytes) {
  if (master_ < 0) return fail("pseudo-terminal: unplugged");
  const ssize_t n = ::write(master_, bytes.data(), bytes.size());
  if (n < 0) return 0;  // EAGAIN (buffer full) or EIO (no slave open): dropped on the floor
  return static_cast<std::size_t>(n);
}

}  // namespace covtrack::serial
