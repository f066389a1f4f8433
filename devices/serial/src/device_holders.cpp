#include "covtrack/devices/serial/device_holders.hpp"

#include <sys/stat.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <system_error>

#include <fmt/format.h>

namespace covtrack::serial {

std::string describe_process(int pid) {
  std::string name;
  std::ifstream comm(fmt::format("/proc/{}/comm", pid));
  std::getline(comm, name);
  return name.empty() ? fmt::format("pid {}", pid) : fmt::format("{} (pid {})", name, pid);
}

std::vector<std::string> processes_holding(const std::string& path) {
  namespace fs = std::filesystem;
  std::vector<std::string> holders;
  struct stat device {};
  if (::stat(path.c_str(), &device) != 0) return holders;
  std::error_code ec;
  for (const fs::directory_entry& process : fs::directory_iterator("/proc", ec)) {
    const std::string pid = process.path().filename().string();
    if (pid.empty() || !std::isdigit(static_cast<unsigned char>(pid[0]))) continue;
    // The same device is the same (st_dev, st_rdev, st_ino) whatever name opened it.
    for (const fs::directory_entry& fd : fs::directory_iterator(process.path() / "fd", ec)) {
      struct stat target {};
      if (::stat(fd.path().c_str(), &target) != 0) continue;
      if (target.st_ino != device.st_ino || target.st_dev != device.st_dev ||
          target.st_rdev != device.st_rdev)
        continue;
      holders.push_back(describe_process(std::stoi(pid)));
      break;
    }
    ec.clear();  // a process that ended or hides its descriptors: go on
  }
  return holders;
}

}  // namespace covtrack::serial
