#pragma once
// Hosts every configured device and publishes their heartbeats.
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "config.hpp"
#include "device_runner.hpp"
#include "publisher.hpp"
#include "publisher_identity.hpp"

namespace covtrack::server {

class Host {
 public:
  Host(const DaemonConfig& config, lcm::LCM& lcm);
  ~Host();

  // Before start(): every published pose also goes to `tap` (see Publisher::tap_poses).
  void tap_poses(Publisher::PoseTap tap) { publisher_.tap_poses(std::move(tap)); }
  // Starts every device but those named in `not_started` (another daemon publishes them).
  void start(const std::set<std::string>& not_started = {});
  // Stops the device's driver and its heartbeats for good; false when no device of this
  // host is left running.
  bool give_up(const std::string& device);
  const PublisherIdentity& identity() const { return identity_; }
  // Asks every device and the heartbeat to stop, and waits for each device's thread up
  // to daemon.stop_timeout_s in all. Returns a line per device whose thread is still
  // running then ("device 'cam' (fiducial) did not stop within 2.0 s"): its driver is
  // blocked in a call that ignores the stop request. The Host must then not be
  // destroyed (it would wait for that thread); the caller ends the process instead.
  std::vector<std::string> stop();

 private:
  void publish_heartbeats(std::stop_token stop);

  DaemonSettings settings_;
  PublisherIdentity identity_ = PublisherIdentity::of_this_process();
  Publisher publisher_;
  std::vector<std::unique_ptr<DeviceRunner>> runners_;
  std::jthread heartbeat_thread_;
};

}  // namespace covtrack::server
