// One program per serial port, on real pseudo-terminals: the UUCP lock file with our pid,
// a second open refused naming the holder (this process, another process, a program that
// uses flock alone), a stale lock file of a dead pid taken over, and flock alone when the
// lock directory cannot be written. The lock directory is a temporary one.
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "covtrack/devices/serial/device_holders.hpp"
#include "covtrack/devices/serial/port_lock.hpp"
#include "covtrack/devices/serial/pseudo_terminal.hpp"
#include "covtrack/devices/serial/serial_port.hpp"

using covtrack::serial::describe_process;
using covtrack::serial::lock_file_path;
using covtrack::serial::PseudoTerminal;
using covtrack::serial::SerialPort;

namespace {

class SerialLock : public ::testing::Test {
 protected:
  void SetUp() override {
    lock_dir_ = ::testing::TempDir() + "/covtrack_locks_" + std::to_string(::getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::filesystem::remove_all(lock_dir_);
    std::filesystem::create_directories(lock_dir_);
    auto pty = PseudoTerminal::create(lock_dir_ + "/tty");
    ASSERT_TRUE(pty) << pty.error().message;
    pty_.emplace(std::move(*pty));
  }
  void TearDown() override {
    pty_.reset();
    std::filesystem::remove_all(lock_dir_);
  }
  covtrack::Result<std::unique_ptr<SerialPort>> open(const std::string& lock_dir) {
    return SerialPort::open({.path = pty_->device_path(), .baud = 19200, .lock_dir = lock_dir});
  }
  covtrack::Result<std::unique_ptr<SerialPort>> open() { return open(lock_dir_); }
  std::string lock_file() const { return lock_file_path(pty_->device_path(), lock_dir_); }

  std::string lock_dir_;
  std::optional<PseudoTerminal> pty_;
};

std::string read_file(const std::string& path) {
  std::stringstream s;
  s << std::ifstream(path).rdbuf();
  return s.str();
}

std::string uucp_pid(int pid) {
  char text[16];
  std::snprintf(text, sizeof text, "%10d\n", pid);
  return text;
}

// A child process that runs `hold` (which takes the port), says so on a pipe, and keeps
// what it took until the parent closes the other pipe.
class Holder {
 public:
  template <typename Hold>
  explicit Holder(Hold hold) {
    int ready[2], release[2];
    if (::pipe(ready) != 0 || ::pipe(release) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::close(ready[0]);
      ::close(release[1]);
      {
        auto held = hold();
        const char ok = held ? 'y' : 'n';
        [[maybe_unused]] auto w = ::write(ready[1], &ok, 1);
        char c;
        [[maybe_unused]] auto r = ::read(release[0], &c, 1);  // returns at the parent's close
      }
      ::_exit(0);
    }
    ::close(ready[1]);
    ::close(release[0]);
    release_fd_ = release[1];
    char ok = 'n';
    holding_ = ::read(ready[0], &ok, 1) == 1 && ok == 'y';
    ::close(ready[0]);
  }
  ~Holder() { end(); }
  bool holding() const { return holding_; }
  pid_t pid() const { return pid_; }
  // Lets the child go and waits for it to exit.
  void end() {
    if (release_fd_ >= 0) ::close(release_fd_);
    release_fd_ = -1;
    if (pid_ > 0) ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
  int release_fd_ = -1;
  bool holding_ = false;
};

}  // namespace

TEST(SerialLockName, IsTheDevicesNameUnderDevWithSlashesAsUnderscores) {
  EXPECT_EQ(lock_file_path("/dev/covtrack-no-such-ttyUSB9", "/run/lock"), "/run/lock/LCK..covtrack-no-such-ttyUSB9");
  auto pty = PseudoTerminal::create(::testing::TempDir() + "/covtrack_lockname_" + std::to_string(::getpid()));
  ASSERT_TRUE(pty) << pty.error().message;
  // Through the link, the device it points to: /dev/pts/N.
  const std::string n = pty->slave_path().substr(std::string("/dev/pts/").size());
  EXPECT_EQ(lock_file_path(pty->device_path(), "/x"), "/x/LCK..pts_" + n);
}

TEST_F(SerialLock, OpenWritesOurPidAndASecondOpenIsRefusedNamingTheHolder) {
  auto first = open();
  ASSERT_TRUE(first) << first.error().message;
  EXPECT_EQ(read_file(lock_file()), uucp_pid(::getpid()));

  auto second = open();
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().message.find("in use by " + describe_process(::getpid())), std::string::npos)
      << second.error().message;
  EXPECT_NE(second.error().message.find(lock_file()), std::string::npos) << second.error().message;

  first->reset();  // closing the port removes the lock file
  EXPECT_FALSE(std::filesystem::exists(lock_file()));
  auto again = open();
  EXPECT_TRUE(again) << again.error().message;
}

TEST_F(SerialLock, AnotherProcessHoldingThePortIsNamedAndReleasesItWhenItEnds) {
  Holder holder([&] { return open(); });
  ASSERT_TRUE(holder.holding());
  const std::string expected = describe_process(holder.pid());
  EXPECT_NE(expected.find("(pid "), std::string::npos) << "no name from /proc: " << expected;

  auto refused = open();
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("in use by " + expected), std::string::npos) << refused.error().message;

  holder.end();
  auto taken = open();
  EXPECT_TRUE(taken) << taken.error().message;
}

TEST_F(SerialLock, AStaleLockFileOfADeadProcessIsTakenOver) {
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ASSERT_EQ(::waitpid(dead, nullptr, 0), dead);  // reaped: no process has this pid now
  std::ofstream(lock_file()) << uucp_pid(dead);

  auto port = open();
  ASSERT_TRUE(port) << port.error().message;
  EXPECT_EQ(read_file(lock_file()), uucp_pid(::getpid()));
}

TEST_F(SerialLock, ALockFileWithoutAPidIsStale) {
  std::ofstream(lock_file()) << "garbage\n";
  auto port = open();
  ASSERT_TRUE(port) << port.error().message;
  EXPECT_EQ(read_file(lock_file()), uucp_pid(::getpid()));
}

TEST_F(SerialLock, AProgramThatUsesFlockAloneIsNamed) {
  Holder holder([&] {
    const int fd = ::open(pty_->device_path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    return fd >= 0 && ::flock(fd, LOCK_EX | LOCK_NB) == 0;  // the descriptor stays open in the child
  });
  ASSERT_TRUE(holder.holding());
  auto refused = open();
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("flock"), std::string::npos) << refused.error().message;
  EXPECT_NE(refused.error().message.find(describe_process(holder.pid())), std::string::npos)
      << refused.error().message;
  // The refused open left no lock file behind.
  EXPECT_FALSE(std::filesystem::exists(lock_file()));
}

TEST_F(SerialLock, WithoutAWritableLockDirectoryFlockAloneStillRefusesASecondOpen) {
  const std::string missing = lock_dir_ + "/no-such-dir";
  auto first = open(missing);
  ASSERT_TRUE(first) << first.error().message;
  auto second = open(missing);
  ASSERT_FALSE(second);
  EXPECT_NE(second.error().message.find("flock"), std::string::npos) << second.error().message;
  first->reset();
  EXPECT_TRUE(open(missing));
}
