#pragma once
// One protocol's conversation with a unit: the reset and configuration sequence up to
// continuous output, and the decoding of what it then streams.
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "covtrack/devices/serial6dof/serial6dof_driver.hpp"
#include "device_link.hpp"
#include "tracker_record.hpp"

namespace covtrack::serial6dof {

class DeviceSession {
 public:
  virtual ~DeviceSession() = default;
  // Resets the unit if asked, configures it (units confirmed, output lists, stations)
  // and starts continuous output. An error says what the unit failed to do.
  virtual Result<void> start(DeviceLink& link, bool reset) = 0;
  virtual std::vector<DecodedItem> feed(std::span<const std::uint8_t> bytes) = 0;
  virtual std::uint64_t resyncs() const = 0;
  virtual std::uint64_t bad_records() const = 0;
  virtual std::string last_problem() const = 0;
};

std::unique_ptr<DeviceSession> make_fastrak_session(const Serial6dofConfig& config);
std::unique_ptr<DeviceSession> make_liberty_session(const Serial6dofConfig& config);
std::unique_ptr<DeviceSession> make_flock_session(const Serial6dofConfig& config);

// What every protocol's session shares: its config, and its decoder, which is handed the
// stream and asked for the counters.
template <typename Decoder>
class DecodingSession : public DeviceSession {
 public:
  DecodingSession(const Serial6dofConfig& config, const auto& format) : config_(config), decoder_(format) {}

  std::vector<DecodedItem> feed(std::span<const std::uint8_t> b) override { return decoder_.feed(b); }
  std::uint64_t resyncs() const override { return decoder_.resyncs(); }
  std::uint64_t bad_records() const override { return decoder_.bad_records(); }
  std::string last_problem() const override { return decoder_.last_problem(); }

 protected:
  // The error for a unit that did not answer (`what_and_when`) in time, with what to check.
  std::unexpected<Error> no_answer(const DeviceLink& link, const std::string& what_and_when,
                                   std::string_view unit_state) const {
    return fail(fmt::format("{}: {} (check the port, the baud rate {} and that {})", link.path(), what_and_when,
                            config_.baud, unit_state));
  }

  Serial6dofConfig config_;
  Decoder decoder_;
};

// Reads and decodes until `accept` takes a reply, or `timeout_s` passes (nullopt).
template <typename Accept>
Result<std::optional<DeviceReply>> await_reply(DeviceLink& link, DeviceSession& session,
                                                double timeout_s, Accept accept) {
  using namespace std::chrono;
  const auto deadline = link.after(timeout_s);
  std::vector<std::uint8_t> bytes;
  while (!link.stopped() && link.clock().now() < deadline) {
    bytes.clear();
    auto n = link.read(bytes, milliseconds(20));
    if (!n) return std::unexpected(n.error());
    for (auto& item : session.feed(bytes))
      if (auto* reply = std::get_if<DeviceReply>(&item); reply && accept(*reply)) return *reply;
  }
  return std::optional<DeviceReply>{};
}

}  // namespace covtrack::serial6dof
