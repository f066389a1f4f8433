#include "covtrack/devices/serial/baud_rate.hpp"

#include <algorithm>
#include <array>

namespace covtrack::serial {

bool is_supported_baud(int baud) {
  static constexpr std::array kRates{1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600};
  return std::ranges::find(kRates, baud) != kRates.end();
}

}  // namespace covtrack::serial
