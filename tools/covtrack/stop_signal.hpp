#pragma once
// SIGINT / SIGTERM as a flag that the commands' loops poll.
#include <atomic>
#include <csignal>

namespace covtrack::cli {

// Lock-free, so that a signal handler may set it.
static_assert(std::atomic<bool>::is_always_lock_free);

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
