#pragma once
// The daemon's single LCM publisher. Drivers reach it through their DeviceSink; it
// stamps publish time and the per-stream sequence numbers, which survive driver restarts
// so that a client sees a gap only when a message was really lost. With a key, it signs
// every message (message_auth.hpp).
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>

#include <lcm/lcm-cpp.hpp>

#include <covtrack/device_status_t.hpp>

#include "covtrack/devices/driver.hpp"
#include "covtrack/protocol/message_auth.hpp"

namespace covtrack::server {

class Publisher {
 public:
  explicit Publisher(lcm::LCM& lcm, std::optional<MessageSigner> signer = std::nullopt)
      : lcm_(lcm), signer_(std::move(signer)) {}

  // Sees every pose after it is published (the VRPN server). Set before the devices
  // start; it runs on the device's thread, so it must not block.
  using PoseTap = std::function<void(const std::string& device, const PoseSample& sample)>;
  void tap_poses(PoseTap tap) { tap_ = std::move(tap); }

  // Each returns false if LCM failed to send (the caller counts it as a drop).
  bool pose(const std::string& device, const PoseSample& sample);
  bool truth(const std::string& device, const TruthSample& sample);
  bool raw(const std::string& device, ByteDirection direction, const std::uint8_t* data,
           std::size_t size);
  bool image(const std::string& device, const ImageSample& sample);
  bool status(const device_status_t& status);

 private:
  std::int64_t next_sequence(const std::string& channel);
  template <typename Msg>
  bool send(const std::string& channel, const Msg& msg);
  // While the host has no route to the group (its interface down, say), every send fails
  // and no heartbeat reaches anyone: the log says so when it starts and when it ends,
  // not once per message.
  void log_send_outcome(bool sent, const std::string& channel, int error);

  lcm::LCM& lcm_;
  std::optional<MessageSigner> signer_;  // under mutex_, which orders its counter as the sends
  PoseTap tap_;
  std::mutex mutex_;  // LCM's publish is thread-safe; this guards the counters and buffer
  std::unordered_map<std::string, std::int64_t> sequences_;
  std::vector<std::uint8_t> buffer_;
  std::int64_t unsent_ = 0;  // messages not sent since sending last failed, 0 while it works
  std::chrono::steady_clock::time_point failing_since_;
};

}  // namespace covtrack::server
