#pragma once
// A DriverClock whose time moves only when the test says, for driver and emulator tests
// on simulated time. The loops still talk over their real ports; only time is simulated.
//
// A loop waiting on this clock (io_timeout with nothing due, or sleep_until) blocks until
// the time moves, so each move runs every loop at least once, and a loop blocks only
// once it has done all the work due by then. settle() waits for that: after advance()
// and settle(n), each of the n loops has caught up with the new time. Bytes a loop sent
// within a step may reach the other side in that step or in the next one, as a real
// line delivers them a little later; a step shorter than the latency a driver allows
// for keeps that harmless.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

#include "covtrack/devices/driver_clock.hpp"

namespace covtrack::test {

class ManualClock final : public DriverClock {
 public:
  // Midnight UTC, 1 January 2026: a fixed wire time, so runs repeat exactly.
  static constexpr std::int64_t kStartUs = 1'767'225'600'000'000;

  time_point now() const override {
    std::lock_guard lock(m_);
    return now_;
  }
  std::int64_t now_us() const override {
    return kStartUs + std::chrono::duration_cast<std::chrono::microseconds>(now() - kStart).count();
  }
  double elapsed_s() const { return std::chrono::duration<double>(now() - kStart).count(); }

  std::chrono::milliseconds io_timeout(std::stop_token stop, time_point due, std::chrono::milliseconds) override {
    std::unique_lock lock(m_);
    if (due > now_) wait_for_a_move(lock, stop);
    return std::chrono::milliseconds(0);
  }

  bool sleep_until(std::stop_token stop, time_point deadline) override {
    std::unique_lock lock(m_);
    while (now_ < deadline && !stop.stop_requested()) wait_for_a_move(lock, stop);
    return !stop.stop_requested();
  }

  void advance(duration d) {
    {
      std::lock_guard lock(m_);
      now_ += d;
      ++moves_;
      idle_ = 0;  // every waiter wakes up and has the new time to catch up with
    }
    cv_.notify_all();
  }

  // Waits until `loops` loops wait on this clock at its current time (each has done
  // what was due), counting those that left(). False after `timeout` of real time.
  bool settle(int loops, std::chrono::seconds timeout = std::chrono::seconds(30)) {
    std::unique_lock lock(m_);
    return cv_.wait_for(lock, timeout, [&] { return idle_ + left_ >= loops; });
  }

  // A loop that will not wait on this clock again (its thread returned).
  void left() {
    {
      std::lock_guard lock(m_);
      ++left_;
    }
    cv_.notify_all();
  }

 private:
  static constexpr time_point kStart = time_point(std::chrono::hours(1));

  void wait_for_a_move(std::unique_lock<std::mutex>& lock, std::stop_token stop) {
    const std::uint64_t entered = moves_;
    ++idle_;
    cv_.notify_all();  // settle() may be waiting for this loop
    cv_.wait(lock, stop, [&] { return moves_ != entered; });
    if (moves_ == entered) --idle_;  // stopped, not moved: no longer waiting
  }

  mutable std::mutex m_;
  std::condition_variable_any cv_;
  time_point now_ = kStart;
  std::uint64_t moves_ = 0;
  int idle_ = 0, left_ = 0;
};

}  // namespace covtrack::test
