#pragma once
// Starts covtrackd as a separate process for end-to-end tests, and stops it with a signal.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include <covtrack/device_status_t.hpp>

namespace covtrack::test {

class DaemonProcess {
 public:
  DaemonProcess(const std::string& config_text, const std::string& lcm_url) {
    config_path_ = ::testing::TempDir() + "/covtrackd_e2e_" + std::to_string(getpid()) + ".toml";
    std::ofstream(config_path_) << config_text;
    pid_ = fork();
    if (pid_ == 0) {
      const std::string exe = COVTRACK_BINARY_DIR "/server/covtrackd";
      execl(exe.c_str(), exe.c_str(), "--config", config_path_.c_str(), "--lcm-url",
            lcm_url.c_str(), "--log-level", "warn", nullptr);
      _exit(127);
    }
  }
  // covtrackd with exactly these arguments; its stdout and stderr go to `output_path`.
  DaemonProcess(const std::vector<std::string>& args, const std::string& output_path)
      : DaemonProcess(COVTRACK_BINARY_DIR "/server/covtrackd", args, output_path) {}
  // Another program the same way (`covtrack echo`, ...).
  DaemonProcess(const std::string& exe, const std::vector<std::string>& args, const std::string& output_path) {
    pid_ = fork();
    if (pid_ == 0) {
      const int out = ::open(output_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (out >= 0) {
        dup2(out, STDOUT_FILENO);
        dup2(out, STDERR_FILENO);
      }
      std::vector<char*> argv{const_cast<char*>(exe.c_str())};
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(exe.c_str(), argv.data());
      _exit(127);
    }
  }
  ~DaemonProcess() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }

  pid_t pid() const { return pid_; }

  // Sends the signal; returns the seconds until the process exited (or -1 after 5 s)
  // and its exit status through `status`.
  double stop(int signal, int& status) {
    const auto t0 = std::chrono::steady_clock::now();
    kill(pid_, signal);
    if (auto ended = wait(5.0)) {
      status = *ended;
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return -1;
  }

  // Waits up to `seconds` for the process to end; its exit status, or nothing.
  std::optional<int> wait(double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    int status = 0;
    while (std::chrono::steady_clock::now() < end) {
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return status;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return std::nullopt;
  }

 private:
  std::string config_path_;
  pid_t pid_ = -1;
  bool exited_ = false;
};

// Handles every message `lcm` receives for `seconds` (polling in 20 ms slices, so the
// loop ends on time even when nothing arrives).
inline void handle_for(lcm::LCM& lcm, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  pollfd pfd{lcm.getFileno(), POLLIN, 0};
  while (std::chrono::steady_clock::now() < end)
    if (poll(&pfd, 1, 20) > 0) lcm.handle();
}

// Keeps the latest heartbeat of one device.
class StatusWatch {
 public:
  StatusWatch(const std::string& url, const std::string& device) : lcm_(url) {
    lcm_.subscribe("covtrack/status/" + device, &StatusWatch::on_status, this);
  }
  // Handles heartbeats until one satisfies `done` or `seconds` passed; the latest one.
  std::optional<device_status_t> until(const std::function<bool(const device_status_t&)>& done, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    pollfd pfd{lcm_.getFileno(), POLLIN, 0};
    while (std::chrono::steady_clock::now() < end && !(last_ && done(*last_)))
      if (poll(&pfd, 1, 20) > 0) lcm_.handle();
    return last_;
  }

 private:
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const device_status_t* m) { last_ = *m; }
  lcm::LCM lcm_;
  std::optional<device_status_t> last_;
};

}  // namespace covtrack::test
