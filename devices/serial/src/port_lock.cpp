#include "covtrack/devices/serial/port_lock.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <expected>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "covtrack/devices/serial/device_holders.hpp"

namespace covtrack::serial {
namespace {

// The pid a lock file holds: ASCII (HDB UUCP, "%10d\n", the form everyone writes today).
// Nothing when the file is missing or holds no pid.
std::optional<int> read_lock_pid(const std::string& file) {
  std::ifstream in(file);
  long pid = 0;
  if (!(in >> pid) || pid <= 0 || pid > INT32_MAX) return std::nullopt;
  return static_cast<int>(pid);
}

// kill(pid, 0) fails with ESRCH only when no such process exists; EPERM means it lives
// under another user.
bool alive(int pid) { return ::kill(pid, 0) == 0 || errno != ESRCH; }

// Lock directories that cannot hold our lock file: locking goes on with flock alone.
bool unwritable(int error) { return error == EACCES || error == EPERM || error == EROFS || error == ENOENT; }

// A temporary file holding our pid, linked into place below: link() either creates the
// lock file whole or fails with EEXIST, so no reader ever sees a half-written one.
// On failure, the errno.
std::expected<std::string, int> write_temporary(const std::string& lock_dir) {
  static std::atomic<int> counter{0};
  const std::string tmp = fmt::format("{}/LTMP.{}.{}", lock_dir, ::getpid(), counter++);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return std::unexpected(errno);
  const std::string content = fmt::format("{:10d}\n", ::getpid());
  const bool written = ::write(fd, content.data(), content.size()) == static_cast<ssize_t>(content.size());
  const int error = errno;
  ::close(fd);
  if (!written) {
    ::unlink(tmp.c_str());
    return std::unexpected(error);
  }
  return tmp;
}

}  // namespace

std::string default_lock_dir() {
  const char* dir = std::getenv("COVTRACK_LOCK_DIR");
  return dir && *dir ? dir : "/var/lock";
}

std::string lock_file_path(const std::string& device_path, const std::string& lock_dir) {
  std::error_code ec;
  std::string name = std::filesystem::canonical(device_path, ec).string();
  if (ec) name = device_path;
  if (name.starts_with("/dev/")) name.erase(0, 5);
  while (!name.empty() && name.front() == '/') name.erase(0, 1);
  for (char& c : name)
    if (c == '/') c = '_';
  return lock_dir + "/LCK.." + name;
}

std::string lock_file_holder(const std::string& device_path, const std::string& lock_dir) {
  const auto pid = read_lock_pid(lock_file_path(device_path, lock_dir));
  return pid && alive(*pid) ? describe_process(*pid) : std::string();
}

Result<PortLock> PortLock::acquire(const std::string& device_path, const std::string& lock_dir) {
  const std::string file = lock_file_path(device_path, lock_dir);
  auto tmp = write_temporary(lock_dir);
  if (!tmp) {
    if (!unwritable(tmp.error()))
      return fail(fmt::format("cannot write a lock file in {}: {}", lock_dir, std::strerror(tmp.error())));
    spdlog::debug("serial port {}: lock directory {} is not writable ({}); locking with flock alone", device_path,
                  lock_dir, std::strerror(tmp.error()));
    return PortLock(device_path, {});
  }
  // Two tries: the second after removing a stale lock file.
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (::link(tmp->c_str(), file.c_str()) == 0) {
      ::unlink(tmp->c_str());
      return PortLock(device_path, file);
    }
    const int error = errno;
    if (error != EEXIST) {
      ::unlink(tmp->c_str());
      return fail(fmt::format("cannot create the lock file {}: {}", file, std::strerror(error)));
    }
    const auto holder = read_lock_pid(file);
    if (holder && alive(*holder)) {
      ::unlink(tmp->c_str());
      return fail(fmt::format("in use by {} (lock file {})", describe_process(*holder), file));
    }
    spdlog::info("serial port {}: removing the stale lock file {} ({})", device_path, file,
                 holder ? fmt::format("pid {} is not running", *holder) : std::string("it holds no pid"));
    ::unlink(file.c_str());
  }
  ::unlink(tmp->c_str());
  return fail(fmt::format("the lock file {} keeps coming back: another program is taking the port", file));
}

Result<void> PortLock::flock_port(int fd) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return {};
  const int error = errno;
  if (error != EWOULDBLOCK) return fail(fmt::format("cannot flock the port: {}", std::strerror(error)));
  std::vector<std::string> holders = processes_holding(device_path_);
  std::erase(holders, describe_process(::getpid()));  // ours is the descriptor just opened
  ::close(fd_);
  fd_ = -1;
  if (holders.empty()) return fail("in use: another descriptor holds its flock (in this process, or hidden from us)");
  return fail(fmt::format("in use: another program holds its flock; open in: {}", fmt::join(holders, ", ")));
}

PortLock::PortLock(PortLock&& other) noexcept
    : device_path_(std::move(other.device_path_)),
      file_(std::exchange(other.file_, {})),
      fd_(std::exchange(other.fd_, -1)) {}

PortLock& PortLock::operator=(PortLock&& other) noexcept {
  if (this != &other) {
    release();
    device_path_ = std::move(other.device_path_);
    file_ = std::exchange(other.file_, {});
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

PortLock::~PortLock() { release(); }

void PortLock::release() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (file_.empty()) return;
  // Only our own: a lock file that another program took over after ours was removed
  // (by hand, say) stays.
  if (read_lock_pid(file_) == ::getpid()) ::unlink(file_.c_str());
  file_.clear();
}

}  // namespace covtrack::serial
