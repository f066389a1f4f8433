#pragma once
// Waits for a condition that other processes make true (a daemon's messages, a command's
// output), checking it every 10 ms. The deadline is generous: only a failure waits for it.
#include <chrono>
#include <thread>

namespace covtrack::testing {

template <typename Condition>
bool wait_for(Condition condition, std::chrono::seconds deadline = std::chrono::seconds(20)) {
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return condition();
}

}  // namespace covtrack::testing
