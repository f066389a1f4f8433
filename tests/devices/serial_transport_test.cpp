// The serial transport over a real pseudo-terminal: bytes both ways, read timeouts, a
// device that is unplugged (error, not exception or crash) and plugged back in, and
// paths that are not serial devices at all.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

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
