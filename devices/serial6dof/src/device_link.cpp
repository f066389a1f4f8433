#include "device_link.hpp"

#include "covtrack/devices/interruptible_sleep.hpp"

namespace covtrack::serial6dof {

using namespace std::chrono;

Result<void> DeviceLink::send(std::string_view bytes) {
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (publish_raw_) sink_.raw(ByteDirection::ToDevice, data, bytes.size());
  return port_.write_all({data, bytes.size()}, milliseconds(500));
}

Result<std::size_t> DeviceLink::read(std::vector<std::uint8_t>& out, milliseconds timeout) {
  std::uint8_t buffer[4096];
  auto n = port_.read_some(buffer, timeout);
  if (!n) return n;
  if (*n && publish_raw_) sink_.raw(ByteDirection::FromDevice, buffer, *n);
  out.insert(out.end(), buffer, buffer + *n);
  return n;
}

Result<void> DeviceLink::drain(milliseconds quiet) {
  const auto give_up = steady_clock::now() + seconds(1);  // a unit still streaming
  std::vector<std::uint8_t> discard;
  while (!stopped() && steady_clock::now() < give_up) {
    discard.clear();
    auto n = read(discard, quiet);
    if (!n) return std::unexpected(n.error());
    if (*n == 0) return {};
  }
  return {};
}

bool DeviceLink::sleep(double seconds) {
  return sleep_for(stop_, duration<double>(seconds));
}

}  // namespace covtrack::serial6dof
