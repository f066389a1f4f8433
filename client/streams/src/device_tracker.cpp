#include "covtrack/client/device_tracker.hpp"

#include <fmt/format.h>

namespace covtrack::client {

std::string DevicePublisher::name() const { return fmt::format("{}/{}", host, pid); }

std::string second_publisher_warning(const std::string& device, const DeviceState& state) {
  const auto& who = state.publishing;
  if (who.size() < 2) return {};
  static constexpr const char* kCount[] = {"", "", "two", "three", "four"};
  std::string names;
  for (std::size_t i = 0; i < who.size(); ++i)
    names += (i == 0 ? "" : i + 1 == who.size() ? " and " : ", ") + who[i].name();
  return fmt::format("device {} published by {} daemons: {}", device,
                     who.size() < std::size(kCount) ? kCount[who.size()] : std::to_string(who.size()), names);
}

void DeviceTracker::on_heartbeat(const device_status_t& status, std::int64_t now_us) {
  auto [it, is_new] = instances_.try_emplace(
      status.instance_id, Instance{{status.instance_id, status.host, status.pid}, now_us, now_us});
  if (is_new) {
    // The one before is already forgotten (silent for long): it was a restart.
    if (newest_ && !instances_.contains(*newest_)) ++state_.restarts;
    newest_ = status.instance_id;
  } else if (status.instance_id != newest_) {
    it->second.overlapped = true;
  }
  it->second.last_us = now_us;
  state_.status = status;
  state_.last_heard_us = now_us;
  state_.reachable = true;
  count_publishers();
}

bool DeviceTracker::check(std::int64_t now_us) {
  for (auto it = instances_.begin(); it != instances_.end();) {
    if (now_us - it->second.last_us <= silence_limit_us()) {
      ++it;
      continue;
    }
    // Silent since a newer one took over, and never heard beside it: a restart.
    if (it->first != newest_ && !it->second.overlapped) ++state_.restarts;
    it = instances_.erase(it);
  }
  count_publishers();
  const bool was_reachable = state_.reachable;
  state_.reachable = state_.last_heard_us > 0 && now_us - state_.last_heard_us <= silence_limit_us();
  return was_reachable && !state_.reachable;
}

void DeviceTracker::count_publishers() {
  if (!newest_) return;
  const auto newest = instances_.find(*newest_);
  if (newest == instances_.end()) return;
  state_.publishing.clear();
  for (const auto& [id, instance] : instances_)
    if (instance.last_us >= newest->second.first_us && id != *newest_) state_.publishing.push_back(instance.who);
  state_.publishing.push_back(newest->second.who);
  state_.publishers = static_cast<int>(state_.publishing.size());
}

}  // namespace covtrack::client
