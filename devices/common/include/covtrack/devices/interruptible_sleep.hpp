#pragma once
// Sleeping that a stop request cuts short, so a driver notices a stop at once.
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <stop_token>

namespace covtrack {

// Returns false if stop was requested (before or during the sleep).
template <typename Clock, typename Duration>
bool sleep_until(std::stop_token stop, std::chrono::time_point<Clock, Duration> deadline) {
  std::mutex m;
  std::condition_variable_any cv;
  std::unique_lock lock(m);
  cv.wait_until(lock, stop, deadline, [] { return false; });
  return !stop.stop_requested();
}

template <typename Rep, typename Period>
bool sleep_for(std::stop_token stop, std::chrono::duration<Rep, Period> d) {
  return sleep_until(stop, std::chrono::steady_clock::now() + d);
}

}  // namespace covtrack
