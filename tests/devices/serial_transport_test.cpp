// The serial transport over a real pseudo-terminal: bytes both ways, read timeouts, a
// device that is unplugged (error, not exception or crash) and plugged back in, and
// paths that are not serial devices at all.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "covtrack/devices/serial/device_holders.hpp"
#include "covtrack/devices/serial/pseudo_terminal.hpp"
#include "covtrack/devices/serial/serial_port.hpp"

using namespace std::chrono_literals;
using covtrack::serial::PseudoTerminal;
using covtrack::serial::SerialPort;
using covtrack::serial::SerialSettings;
using Bytes = std::vector<std::uint8_t>;

namespace {

std::string link_path(const std::string& name) {
  return ::testing::TempDir() + "/covtrack_" + name + "_" + std::to_string(::getpid());
}

// Reads from the driver side until `count` bytes arrived or ~2 s passed.
Bytes read_from_port(SerialPort& port, std::size_t count) {
  Bytes got;
  std::uint8_t buf[256];
  for (int i = 0; i < 40 && got.size() < count; ++i) {
    auto n = port.read_some(buf, 50ms);
    if (!n) break;
    got.insert(got.end(), buf, buf + *n);
  }
  return got;
}

Bytes read_from_pty(PseudoTerminal& pty, std::size_t count) {
  Bytes got;
  std::uint8_t buf[256];
  for (int i = 0; i < 40 && got.size() < count; ++i) {
    auto n = pty.read_some(buf, 50ms);
    if (!n) break;
    got.insert(got.end(), buf, buf + *n);
  }
  return got;
}

}  // namespace

TEST(SerialTransport, BytesFlowBothWaysUnchanged) {
  auto pty = PseudoTerminal::create(link_path("both"));
  ASSERT_TRUE(pty) << pty.error().message;
  auto port = SerialPort::open({.path = pty->device_path(), .baud = 19200, .rts_cts = true});
  ASSERT_TRUE(port) << port.error().message;

  // Every byte value, including CR, LF, XON/XOFF and Ctrl-C, must pass untouched (raw mode).
  Bytes all(256);
  for (int i = 0; i < 256; ++i) all[i] = static_cast<std::uint8_t>(i);
  ASSERT_EQ(*pty->write(all), all.size());
  EXPECT_EQ(read_from_port(**port, all.size()), all);

  ASSERT_TRUE((*port)->write_all(all, 1000ms));
  EXPECT_EQ(read_from_pty(*pty, all.size()), all);
}

TEST(SerialTransport, ReadTimesOutWithNoBytes) {
  auto pty = PseudoTerminal::create();
  ASSERT_TRUE(pty) << pty.error().message;
  auto port = SerialPort::open({.path = pty->device_path(), .baud = 57600});
  ASSERT_TRUE(port) << port.error().message;
  std::uint8_t buf[16];
  auto n = (*port)->read_some(buf, 30ms);
  ASSERT_TRUE(n) << n.error().message;
  EXPECT_EQ(*n, 0u);
  EXPECT_FALSE((*port)->disconnected());
}

// A backlog bigger than one read (a terminal hands out at most 4 KB per read), as after a
// hold-up of the daemon: read_waiting takes all of it in one call, in order.
TEST(SerialTransport, ReadWaitingTakesTheWholeBacklogInOneCall) {
  auto pty = PseudoTerminal::create();
  ASSERT_TRUE(pty) << pty.error().message;
  auto port = SerialPort::open({.path = pty->device_path(), .baud = 115200});
  ASSERT_TRUE(port) << port.error().message;
  // 10 KB: as much as the terminal takes at once (it took 11.5 KB here).
  Bytes backlog(10000);
  for (std::size_t i = 0; i < backlog.size(); ++i) backlog[i] = static_cast<std::uint8_t>(i * 7 + i / 256);
  const auto give_up = std::chrono::steady_clock::now() + 5s;
  for (std::size_t sent = 0; sent < backlog.size(); std::this_thread::yield()) {
    ASSERT_LT(std::chrono::steady_clock::now(), give_up) << "the terminal took no more after " << sent << " bytes";
    auto n = pty->write(std::span(backlog).subspan(sent));
    ASSERT_TRUE(n) << n.error().message;
    sent += *n;
  }
  Bytes got{0xAA};  // appended to, not replaced
  auto n = (*port)->read_waiting(got, 1000ms);
  ASSERT_TRUE(n) << n.error().message;
  EXPECT_EQ(*n, backlog.size());
  ASSERT_EQ(got.size(), backlog.size() + 1);
  EXPECT_EQ(got[0], 0xAA);
  EXPECT_TRUE(std::equal(backlog.begin(), backlog.end(), got.begin() + 1));
  // Nothing more waiting: a wait that ends with no bytes.
  n = (*port)->read_waiting(got, 10ms);
  ASSERT_TRUE(n) << n.error().message;
  EXPECT_EQ(*n, 0u);
}

TEST(SerialTransport, MissingDeviceIsAClearError) {
  auto port = SerialPort::open({.path = "/dev/covtrack-no-such-tty", .baud = 19200});
  ASSERT_FALSE(port);
  EXPECT_NE(port.error().message.find("/dev/covtrack-no-such-tty"), std::string::npos) << port.error().message;
  EXPECT_NE(port.error().message.find("no such device"), std::string::npos) << port.error().message;
}

// Config typos: libserial 1.0.0 aborts the process on a path that opens but is not a
// terminal (it throws again from its destructor), so these must come back as errors.
TEST(SerialTransport, RegularFileIsAClearErrorNotACrash) {
  const std::string path = link_path("plain_file");
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fclose(f);
  auto port = SerialPort::open({.path = path, .baud = 19200});
  ASSERT_FALSE(port);
  EXPECT_NE(port.error().message.find(path), std::string::npos) << port.error().message;
  EXPECT_NE(port.error().message.find("regular file, not a serial device"), std::string::npos)
      << port.error().message;
  std::remove(path.c_str());
}

TEST(SerialTransport, DirectoryIsAClearError) {
  auto port = SerialPort::open({.path = ::testing::TempDir(), .baud = 19200});
  ASSERT_FALSE(port);
  EXPECT_NE(port.error().message.find("directory, not a serial device"), std::string::npos)
      << port.error().message;
}

TEST(SerialTransport, CharacterDeviceThatIsNotATerminalIsAClearErrorNotACrash) {
  for (int attempt = 0; attempt < 3; ++attempt) {  // the teardown must also be repeatable
    auto port = SerialPort::open({.path = "/dev/null", .baud = 19200});
    ASSERT_FALSE(port);
    EXPECT_NE(port.error().message.find("cannot be set up as a terminal"), std::string::npos)
        << port.error().message;
  }
}

// A pseudo-terminal slave that is still locked refuses open() with EIO; libserial would
// report "Bad file descriptor" (it calls close(-1) before reading errno).
TEST(SerialTransport, RefusedOpenReportsTheRealError) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  ASSERT_GE(master, 0);
  ASSERT_EQ(::grantpt(master), 0);
  char name[128];
  ASSERT_EQ(::ptsname_r(master, name, sizeof name), 0);
  auto port = SerialPort::open({.path = name, .baud = 19200});
  ::close(master);
  ASSERT_FALSE(port);
  EXPECT_NE(port.error().message.find(std::strerror(EIO)), std::string::npos) << port.error().message;
  EXPECT_EQ(port.error().message.find(std::strerror(EBADF)), std::string::npos) << port.error().message;
}

TEST(SerialTransport, HoldersOfADeviceAreNamed) {
  auto pty = PseudoTerminal::create(link_path("holders"));
  ASSERT_TRUE(pty) << pty.error().message;
  const std::string me = "(pid " + std::to_string(::getpid()) + ")";
  const auto names_me = [&] {
    for (const std::string& h : covtrack::serial::processes_holding(link_path("holders")))
      if (h.find(me) != std::string::npos) return true;
    return false;
  };
  EXPECT_FALSE(names_me()) << "only the master is open, and it is another device";
  const int slave = ::open(pty->slave_path().c_str(), O_RDWR | O_NOCTTY);
  ASSERT_GE(slave, 0);
  EXPECT_TRUE(names_me()) << "through the symlink, the slave held here";
  ::close(slave);
  EXPECT_FALSE(names_me());
  EXPECT_TRUE(covtrack::serial::processes_holding("/nonexistent/tty").empty());
}

// As under `unshare --map-root-user` (the e2e tests' namespaces): root there cannot
// override TIOCEXCL, so a port held exclusively by one process refuses another with
// EBUSY, and the message says who holds it. A child enters a user namespace and holds
// the port; its own child tries to open it.
TEST(SerialTransport, BusyPortNamesWhoHoldsIt) {
  const std::string path = link_path("busy");  // the children's pids differ
  auto pty = PseudoTerminal::create(path);
  ASSERT_TRUE(pty) << pty.error().message;
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t holder = ::fork();
  ASSERT_GE(holder, 0);
  if (holder == 0) {
    ::close(pipe_fds[0]);
    const auto write_file = [](const char* file, const char* text) {
      const int fd = ::open(file, O_WRONLY);
      const bool ok = fd >= 0 && ::write(fd, text, std::strlen(text)) == static_cast<ssize_t>(std::strlen(text));
      if (fd >= 0) ::close(fd);
      return ok;
    };
    const auto say = [&](const std::string& message) {
      (void)!::write(pipe_fds[1], message.data(), message.size());
      ::_exit(0);
    };
    if (::unshare(CLONE_NEWUSER) != 0 || !write_file("/proc/self/setgroups", "deny") ||
        !write_file("/proc/self/uid_map", "0 0 1\n") || !write_file("/proc/self/gid_map", "0 0 1\n"))
      say("no user namespace");
    const int held = ::open(pty->slave_path().c_str(), O_RDWR | O_NOCTTY);
    if (held < 0 || ::ioctl(held, TIOCEXCL) != 0) say("cannot hold the port");
    const pid_t opener = ::fork();
    if (opener == 0) {
      ::close(held);  // inherited: only the parent holds it
      auto port = SerialPort::open({.path = path, .baud = 19200});
      say(port ? "opened" : port.error().message);
    }
    ::waitpid(opener, nullptr, 0);
    ::_exit(0);
  }
  ::close(pipe_fds[1]);
  std::string message;
  char buf[512];
  for (ssize_t n; (n = ::read(pipe_fds[0], buf, sizeof buf)) > 0;) message.append(buf, static_cast<std::size_t>(n));
  ::close(pipe_fds[0]);
  ::waitpid(holder, nullptr, 0);
  if (message == "no user namespace") GTEST_SKIP() << "this machine gives no user namespace";
  EXPECT_NE(message.find(std::strerror(EBUSY)), std::string::npos) << message;
  EXPECT_NE(message.find("(pid " + std::to_string(holder) + ")"), std::string::npos) << message;
}

TEST(SerialTransport, UnsupportedBaudIsRejected) {
  auto pty = PseudoTerminal::create();
  ASSERT_TRUE(pty);
  auto port = SerialPort::open({.path = pty->device_path(), .baud = 12345});
  ASSERT_FALSE(port);
  EXPECT_NE(port.error().message.find("12345"), std::string::npos) << port.error().message;
}

TEST(SerialTransport, UnplugIsAnErrorAndReplugWorksAgain) {
  auto pty = PseudoTerminal::create(link_path("replug"));
  ASSERT_TRUE(pty) << pty.error().message;
  const std::string path = pty->device_path();
  {
    auto port = SerialPort::open({.path = path, .baud = 19200});
    ASSERT_TRUE(port) << port.error().message;
    const Bytes hello{0x21, 0x24, 0x05};
    ASSERT_TRUE((*port)->write_all(hello, 500ms));
    EXPECT_EQ(read_from_pty(*pty, 3), hello);

    pty->unplug();
    std::uint8_t buf[16];
    auto n = (*port)->read_some(buf, 500ms);
    ASSERT_FALSE(n) << "read on an unplugged device returned " << *n << " bytes";
    EXPECT_NE(n.error().message.find("disconnected"), std::string::npos) << n.error().message;
    EXPECT_TRUE((*port)->disconnected());
    // Every later call tells the same reason.
    auto again = (*port)->read_some(buf, 500ms);
    ASSERT_FALSE(again);
    EXPECT_EQ(again.error().message, n.error().message);
    EXPECT_FALSE((*port)->write_all(hello, 100ms));
    // The port is destroyed here, on a dead device: this must not terminate the process.
  }
  // While unplugged the device node is gone, as with a USB adapter.
  EXPECT_FALSE(SerialPort::open({.path = path, .baud = 19200}));

  ASSERT_TRUE(pty->replug());
  EXPECT_EQ(pty->device_path(), path);
  auto port = SerialPort::open({.path = path, .baud = 19200});
  ASSERT_TRUE(port) << port.error().message;
  const Bytes reply{0x62, 0x22, 0x00, 0x40};
  ASSERT_EQ(*pty->write(reply), reply.size());
  EXPECT_EQ(read_from_port(**port, reply.size()), reply);
}

TEST(SerialTransport, DriverClosingDoesNotBreakTheEmulator) {
  auto pty = PseudoTerminal::create(link_path("reopen"));
  ASSERT_TRUE(pty);
  for (int round = 0; round < 3; ++round) {
    auto port = SerialPort::open({.path = pty->device_path(), .baud = 19200});
    ASSERT_TRUE(port) << "round " << round << ": " << port.error().message;
    const Bytes b{static_cast<std::uint8_t>(round)};
    ASSERT_TRUE((*port)->write_all(b, 500ms));
    EXPECT_EQ(read_from_pty(*pty, 1), b);
  }
  // With no driver connected the emulator's reads just time out.
  std::uint8_t buf[4];
  auto n = pty->read_some(buf, 20ms);
  ASSERT_TRUE(n);
  EXPECT_EQ(*n, 0u);
}
