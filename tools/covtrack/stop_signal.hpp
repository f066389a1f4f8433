#pragma once
// SIGINT / SIGTERM as a flag that the commands' loops poll.
#include <atomic>
#include <csignal>

namespace covtrack::cli {

inline std::atomic<bool>& stop_requested() {
  static std::atomic<bool> flag{false};
  return flag;
}

inline void install_stop_signals() {
  auto handler = [](int) { stop_requested() = true; };
  std::signal(SIGINT, handler);
  std::signal(SIGTERM, handler);
}

}  // namespace covtrack::cli
