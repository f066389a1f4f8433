#include "covtrack/devices/driver_clock.hpp"

#include <algorithm>

#include "covtrack/devices/interruptible_sleep.hpp"
#include "covtrack/protocol/clock.hpp"

namespace covtrack {
namespace {

class RealClock final : public DriverClock {
 public:
  time_point now() const override { return std::chrono::steady_clock::now(); }
  std::int64_t now_us() const override { return covtrack::now_us(); }
  std::chrono::milliseconds io_timeout(std::stop_token, time_point due, std::chrono::milliseconds cap) override {
    using std::chrono::milliseconds;
    // Rounded up: rounded down, a wait of a fraction of a millisecond would be 0 and the
    // loop would spin on its port until the work is due.
    return std::max(milliseconds(0), std::min(std::chrono::ceil<milliseconds>(due - now()), cap));
  }
  bool sleep_until(std::stop_token stop, time_point deadline) override { return covtrack::sleep_until(stop, deadline); }
};

}  // namespace

DriverClock& real_clock() {
  static RealClock clock;
  return clock;
}

}  // namespace covtrack
