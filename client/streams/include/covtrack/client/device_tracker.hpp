#pragma once
// A device as its heartbeats tell it: the last status, whether it is still heard, and who
// publishes it. The heartbeat carries its publisher's instance id (random per daemon
// start) and the heartbeat period, so a client tells a dead daemon (no heartbeat for
// kMissedHeartbeats periods: unreachable) from a quiet one, a restart (a new instance id,
// the old one silent from then on) from a second publisher (two ids that both go on).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <covtrack/device_status_t.hpp>

namespace covtrack::client {

// One daemon instance that publishes a device, as its heartbeats name it.
struct DevicePublisher {
  std::int64_t instance_id = 0;
  std::string host;
  std::int32_t pid = 0;
  std::string name() const;  // "host/pid"
};

struct DeviceState {
  device_status_t status;          // the last accepted heartbeat
  std::int64_t last_heard_us = 0;  // when it arrived (CLOCK_REALTIME, this client's clock)
  bool reachable = true;           // a heartbeat within the last kMissedHeartbeats periods
  int publishers = 1;              // instance ids heard since the newest one appeared: 2+ is a second publisher
  std::vector<DevicePublisher> publishing;  // those instances, the newest last
  std::int64_t restarts = 0;       // instances that fell silent once a newer one took over
};

// "device rig published by two daemons: pc1/1234 and pc2/99", or empty with one publisher.
std::string second_publisher_warning(const std::string& device, const DeviceState& state);

class DeviceTracker {
 public:
  static constexpr int kMissedHeartbeats = 3;

  void on_heartbeat(const device_status_t& status, std::int64_t now_us);
  // Forgets instances silent for kMissedHeartbeats periods (counting the restarts they
  // reveal) and updates reachable; true when the device has just become unreachable.
  bool check(std::int64_t now_us);
  const DeviceState& state() const { return state_; }

 private:
  struct Instance {
    DevicePublisher who;
    std::int64_t first_us = 0;
    std::int64_t last_us = 0;
    bool overlapped = false;  // heard after a newer instance appeared: a second publisher, not a restart
  };
  std::int64_t silence_limit_us() const { return kMissedHeartbeats * state_.status.heartbeat_period_us; }
  void count_publishers();

  std::map<std::int64_t, Instance> instances_;  // by instance id
  std::optional<std::int64_t> newest_;          // the instance id that appeared last
  DeviceState state_;
};

}  // namespace covtrack::client
