#include "host.hpp"

#include <chrono>

#include <fmt/format.h>

#include "covtrack/devices/interruptible_sleep.hpp"

namespace covtrack::server {
namespace {

std::optional<MessageSigner> signer_of(const DaemonConfig& config, const PublisherIdentity& identity) {
  if (!config.auth_key) return std::nullopt;
  return MessageSigner(*config.auth_key, static_cast<std::uint64_t>(identity.instance_id));
}

}  // namespace

// identity_ is initialised before publisher_: the signer names the same instance as the heartbeats.
Host::Host(const DaemonConfig& config, lcm::LCM& lcm)
    : settings_(config.daemon), publisher_(lcm, signer_of(config, identity_)) {
  for (const auto& device : config.devices)
    runners_.push_back(std::make_unique<DeviceRunner>(device, publisher_, settings_));
}

Host::~Host() {
  // Waits without a limit: a caller that got stuck devices from stop() never gets here.
  heartbeat_thread_.request_stop();
  for (auto& r : runners_) r->request_stop();
  for (auto& r : runners_) r->join();
}

void Host::start(const std::set<std::string>& not_started) {
  for (auto& r : runners_) {
    if (not_started.contains(r->name())) r->release();
    else r->start();
  }
  heartbeat_thread_ = std::jthread([this](std::stop_token stop) { publish_heartbeats(stop); });
}

bool Host::give_up(const std::string& device) {
  bool any_left = false;
  for (auto& r : runners_) {
    if (r->name() == device) r->release();
    any_left = any_left || !r->released();
  }
  return any_left;
}

std::vector<std::string> Host::stop() {
  // Ask everyone first, then wait: the stop takes as long as the slowest, not the sum.
  heartbeat_thread_.request_stop();
  for (auto& r : runners_) r->request_stop();
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(settings_.stop_timeout_s));
  std::vector<std::string> stuck;
  for (auto& r : runners_)
    if (!r->join_until(deadline))
      stuck.push_back(fmt::format("device '{}' ({}) did not stop within {:.1f} s", r->name(), r->type(),
                                  settings_.stop_timeout_s));
  if (heartbeat_thread_.joinable()) heartbeat_thread_.join();
  return stuck;
}

void Host::publish_heartbeats(std::stop_token stop) {
  using namespace std::chrono;
  const auto period = duration_cast<steady_clock::duration>(duration<double>(1.0 / settings_.heartbeat_hz));
  const auto period_us = duration_cast<microseconds>(period).count();
  for (auto next = steady_clock::now() + period; sleep_until(stop, next); next += period)
    for (auto& r : runners_) {
      if (r->released()) continue;  // another daemon publishes it
      device_status_t status = r->heartbeat();
      status.instance_id = identity_.instance_id;
      status.host = identity_.host;
      status.pid = identity_.pid;
      status.heartbeat_period_us = period_us;
      publisher_.status(status);
    }
}

}  // namespace covtrack::server
