#include "device_link.hpp"

namespace covtrack::serial6dof {

using namespace std::chrono;

Result<void> DeviceLink::send(std::string_view bytes) {
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (publish_raw_) sink_.raw(ByteDirection::ToDevice, data, bytes.size());
  return port_.write_all({data, bytes.size()}, milliseconds(500));
}

Result<std::size_t> DeviceLink::read(std::vector<std::uint8_t>& out, milliseconds timeout) {
  return read_until(out, clock_.now() + timeout);
}

Result<std::size_t> DeviceLink::read_until(std::vector<std::uint8_t>& out, DriverClock::time_point until) {
  // All that is waiting, not one read's worth: the caller times a burst of records from
  // its newest, which must be in it (serial_port.hpp, read_waiting).
  const std::size_t before = out.size();
  auto n = port_.read_waiting(out, clock_.io_timeout(stop_, until, ceil<milliseconds>(until - clock_.now())));
  if (n && *n && publish_raw_) sink_.raw(ByteDirection::FromDevice, out.data() + before, *n);
  return n;
}

Result<void> DeviceLink::drain(milliseconds quiet) {
  const auto give_up = after(1.0);  // a unit still streaming
  auto quiet_until = clock_.now() + quiet;
  std::vector<std::uint8_t> discard;
  while (!stopped() && clock_.now() < give_up) {
    discard.clear();
    auto n = read_until(discard, quiet_until);
    if (!n) return std::unexpected(n.error());
    if (*n > 0) quiet_until = clock_.now() + quiet;
    else if (clock_.now() >= quiet_until) return {};
  }
  return {};
}

DriverClock::time_point DeviceLink::after(double seconds) const {
  return clock_.now() + duration_cast<DriverClock::duration>(duration<double>(seconds));
}

bool DeviceLink::sleep(double seconds) { return clock_.sleep_until(stop_, after(seconds)); }

}  // namespace covtrack::serial6dof
