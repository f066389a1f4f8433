#pragma once
// One publisher per device. Two daemons started with the same config would both publish
// every device: clients would see double rates and the second sequence as loss, and two
// drivers on one serial port would reset each other. So daemons tell each other which
// devices they publish, on covtrack/claim/<device> (device_claim_t), and listen to the
// heartbeats of their own devices (protocol/README.md, "One publisher per device"):
//
// - At start, a daemon claims each device (CLAIMING, sent a few times over
//   daemon.claim_wait_s) and listens. A daemon that holds the device answers at once
//   (HOLDING), and its heartbeats say the same: the newcomer does not start that device
//   and says who holds it.
// - Two daemons claiming at once: the smaller (claimed_us, instance_id) goes on, the
//   other does not start the device. Both compare the same two pairs, so exactly one
//   keeps it.
// - Holders that meet later (a claim lost, a wait of 0, hosts joined): each that hears
//   another's heartbeat sends its HOLDING claim; the holder whose pair is larger stops
//   its driver and says why.
// - daemon.allow_duplicate_publishers: this daemon neither refuses nor gives up a device;
//   it says who else publishes it.
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include <covtrack/device_claim_t.hpp>
#include <covtrack/device_status_t.hpp>

#include "claim_listener.hpp"
#include "covtrack/protocol/result.hpp"
#include "publisher_identity.hpp"

namespace covtrack::server {

struct ClaimSettings {
  double wait_s = 0.5;
  bool allow_duplicates = false;
};

class DeviceOwnership {
 public:
  // Called on the listening thread when a device held must be given up; `why` names the
  // daemon that keeps it.
  using GiveUp = std::function<void(const std::string& device, const std::string& why)>;
  // Waits up to the given time; false when the daemon is told to stop meanwhile.
  using Wait = std::function<bool(std::chrono::milliseconds)>;

  // Publishes claims on `lcm` and starts listening for the claims and heartbeats of
  // `devices`: on a udpm:// `url` through a ClaimListener, else (memq://) through `lcm`.
  // Fails when the listener cannot join the group.
  static Result<std::unique_ptr<DeviceOwnership>> open(lcm::LCM& lcm, const std::string& url,
                                                       PublisherIdentity identity,
                                                       const std::vector<std::string>& devices,
                                                       ClaimSettings settings, GiveUp give_up);
  ~DeviceOwnership();
  DeviceOwnership(const DeviceOwnership&) = delete;
  DeviceOwnership& operator=(const DeviceOwnership&) = delete;

  // Claims every device and waits settings.wait_s through `wait`. Returns the devices not
  // to start, each with why; nothing when `wait` was interrupted.
  std::optional<std::map<std::string, std::string>> claim(const Wait& wait);

 private:
  enum class Stage { Claiming, Holding, Refused };
  struct Other {
    std::int64_t claimed_us = 0;  // 0 until a claim of it is heard
    bool holding = false;         // a heartbeat or a HOLDING claim heard
    bool publishing = false;      // a heartbeat heard: it does publish the device
    bool named = false;           // said in the log already
    std::string host;
    std::int32_t pid = 0;
  };
  struct Device {
    Stage stage = Stage::Claiming;
    std::map<std::int64_t, Other> others;  // by instance id
  };

  DeviceOwnership(lcm::LCM& lcm, PublisherIdentity identity, const std::vector<std::string>& devices,
                  ClaimSettings settings, GiveUp give_up);
  void listen(std::stop_token stop);
  void on_message(const std::string& channel, std::span<const std::byte> bytes);
  void on_lcm_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void on_claim(const device_claim_t& claim);
  void on_status(const device_status_t& status);
  void send_claim(const std::string& device, std::int8_t stage);
  // Whether `other` comes before this daemon in the race rule.
  bool comes_first(std::int64_t instance_id, const Other& other) const;
  // Why `device` is not ours, when another daemon holds it or claimed it first.
  std::optional<std::string> held_elsewhere(const Device& device) const;
  void name_once(const std::string& device, std::int64_t instance_id, Other& other);

  lcm::LCM& lcm_;
  const PublisherIdentity identity_;
  const ClaimSettings settings_;
  const GiveUp give_up_;
  std::int64_t claimed_us_ = 0;

  std::mutex mutex_;  // guards devices_
  std::map<std::string, Device> devices_;
  std::unique_ptr<ClaimListener> listener_;    // udpm://
  std::vector<lcm::Subscription*> subscriptions_;  // else
  std::jthread thread_;
};

// "pc1/1234 (instance 0x1f3a...)": how logs name a daemon.
std::string describe_daemon(const std::string& host, std::int32_t pid, std::int64_t instance_id);

}  // namespace covtrack::server
