#pragma once
// Hosts every configured device and publishes their heartbeats.
#include <memory>
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

  void start();
  // Stops every device and the heartbeat, and waits for their threads.
  void stop();

 private:
  void publish_heartbeats(std::stop_token stop);

  DaemonSettings settings_;
  PublisherIdentity identity_ = PublisherIdentity::of_this_process();
  Publisher publisher_;
  std::vector<std::unique_ptr<DeviceRunner>> runners_;
  std::jthread heartbeat_thread_;
};

}  // namespace covtrack::server
