#include "device_link.hpp"

namespace covtrack::serial6dof {

using namespace std::chrono;

namespace {
constexpr int kMostReadsAtOnce = 16;  // of 4 KB each: a backlog of seconds at any unit's rate
}  // namespace

Result<void> DeviceLink::send(std::string_view bytes) {
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (publish_raw_) sink_.raw(ByteDirection::ToDevice, data, bytes.size());
  return port_.write_all({data, bytes.size()}, milliseconds(500));
}

Result<std::size_t> DeviceLink::read(std::vector<std::uint8_t>& out, milliseconds timeout) {
  auto n = read_until(out, clock_.now() + timeout);
  if (!n) return n;
  // Then whatever else is waiting, without waiting: after a hold-up the backlog can
  // exceed one read, and the caller times a burst from its newest record, which must be
  // in it (a split burst would time its first part as if it ended now). An error here
  // shows again at the next read; the bytes already read are kept.
  std::size_t total = *n;
  for (int reads = 1; *n > 0 && reads < kMostReadsAtOnce; ++reads) {
    n = read_until(out, clock_.now());
    if (!n) break;
    total += *n;
  }
  return total;
}

Result<std::size_t> DeviceLink::read_until(std::vector<std::uint8_t>& out, DriverClock::time_point until) {
  std::uint8_t buffer[4096];
  auto n = port_.read_some(buffer, clock_.io_timeout(stop_, until, ceil<milliseconds>(until - clock_.now())));
  if (!n) return n;
  if (*n && publish_raw_) sink_.raw(ByteDirection::FromDevice, buffer, *n);
  out.insert(out.end(), buffer, buffer + *n);
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
