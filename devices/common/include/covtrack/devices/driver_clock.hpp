#pragma once
// The time a driver or an emulator runs on, passed in rather than read from the system,
// so that a test can run the time-dependent logic (keepalives, timeouts, sample
// schedules, dead reckoning) on simulated time: as fast as the machine allows and
// unaffected by how loaded it is. Production code uses real_clock(); tests use a manual
// clock whose time moves only when the test moves it (tests/devices/manual_clock.hpp).
//
// A loop on this clock blocks in one of two places: on its port (io_timeout says for
// how long) or in sleep_until. A manual clock blocks the loop in both until its time has
// moved, so every loop runs at least once per move and the port is only polled.
#include <chrono>
#include <cstdint>
#include <stop_token>

namespace covtrack {

class DriverClock {
 public:
  using time_point = std::chrono::steady_clock::time_point;
  using duration = std::chrono::steady_clock::duration;

  virtual ~DriverClock() = default;
  // Monotonic: deadlines, timeouts, the times dead reckoning works with.
  virtual time_point now() const = 0;
  // The wire time at now(): microseconds since the Unix epoch (protocol/clock.hpp).
  virtual std::int64_t now_us() const = 0;
  // Called by a loop just before it waits on its port, with the next time it has work
  // due: how long the wait may last, at most `cap` (0 if the work is due now).
  virtual std::chrono::milliseconds io_timeout(std::stop_token stop, time_point due,
                                               std::chrono::milliseconds cap) = 0;
  // Waits until `deadline` on this clock; false if stop was requested.
  virtual bool sleep_until(std::stop_token stop, time_point deadline) = 0;

  double now_s() const { return seconds_of(now()); }
  // A time of now() in the seconds of now_s().
  static double seconds_of(time_point t) { return std::chrono::duration<double>(t.time_since_epoch()).count(); }
};

// The system's clocks: steady_clock for now(), CLOCK_REALTIME for now_us().
DriverClock& real_clock();

}  // namespace covtrack
