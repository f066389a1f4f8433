#pragma once
// A DriverClock whose time moves only when the test says, for driver and emulator tests
// on simulated time. The loops still talk over their real ports; only time is simulated.
//
// A loop waiting on this clock (io_timeout with nothing due, or sleep_until) blocks until
// the time moves, so each move runs every loop at least once, and a loop blocks only
// once it has done all the work due by then. settle() waits for that: after advance()
// and settle(), every loop that join()ed has caught up with the new time. Bytes a loop
// sent within a step may reach the other side in that step or in the next one, as a
// real line delivers them a little later; a step shorter than the latency a driver
// allows for keeps that harmless.
//
// io_timeout here returns a wait of 0 ms, so a driver that measures how long it was away
// from its port finds no waits to account for the time between its reads: from one
// read's start to the next read's end, two steps. The Lenz driver counts 20 ms of that as
// a hold-up (lenz_driver.cpp, kHeldUp) and widens the poses after it: keep Lenz steps
// under 10 ms unless a test means a hold-up.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>

#include "covtrack/devices/driver_clock.hpp"

namespace covtrack::test {

class ManualClock final : public DriverClock {
 public:
  explicit ManualClock(duration step = std::chrono::milliseconds(5)) : step_(step) {}

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

  // Waits until every joined loop waits on this clock at its current time (each has
  // done what was due). False after `timeout` of real time.
  bool settle(std::chrono::seconds timeout = std::chrono::seconds(30)) {
    std::unique_lock lock(m_);
    return cv_.wait_for(lock, timeout, [&] { return idle_ >= loops_; });
  }

  // A loop settle() waits for: join() before its thread starts, leave() when it returns.
  void join() {
    std::lock_guard lock(m_);
    ++loops_;
  }
  void leave() {
    {
      std::lock_guard lock(m_);
      --loops_;
    }
    cv_.notify_all();
  }

  // Moves time on by `how_long` in steps, letting every loop catch up after each.
  bool run_for(duration how_long) {
    for (duration done{0}; done < how_long; done += step_)
      if (!step()) return false;
    return true;
  }
  // Moves time on in steps until `done` holds; false if it does not within `limit`.
  bool run_until(const std::function<bool()>& done, duration limit) {
    const time_point end = now() + limit;
    while (!done()) {
      if (now() >= end) {
        ADD_FAILURE() << "still waiting after " << elapsed_s() << " s of simulated time";
        return false;
      }
      if (!step()) return false;
    }
    return true;
  }

 private:
  static constexpr time_point kStart = time_point(std::chrono::hours(1));

  bool step() {
    advance(step_);
    if (settle()) return true;
    ADD_FAILURE() << "a loop did not catch up with the simulated clock at " << elapsed_s() << " s";
    return false;
  }

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
  const duration step_;
  std::uint64_t moves_ = 0;
  int idle_ = 0, loops_ = 0;
};

}  // namespace covtrack::test
