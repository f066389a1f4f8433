#include "covtrack/protocol/replay_guard.hpp"

#include <fmt/format.h>

namespace covtrack {

std::optional<std::string> ReplayGuard::check(std::string_view channel, const AuthTrailer& trailer,
                                              std::int64_t now_us) {
  const std::int64_t age_us = now_us - trailer.sent_us;
  if (age_us > max_age_us_ || -age_us > max_age_us_)
    return fmt::format("sent {:.3f} s {} (the limit is {:.3f} s: a replay, or clocks that disagree)",
                       1e-6 * static_cast<double>(age_us < 0 ? -age_us : age_us), age_us < 0 ? "in the future" : "ago",
                       1e-6 * static_cast<double>(max_age_us_));
  auto it = channels_.find(channel);
  if (it == channels_.end()) it = channels_.emplace(std::string(channel), std::map<std::uint64_t, Seen>{}).first;
  auto& instances = it->second;
  auto seen = instances.find(trailer.instance_id);
  if (seen == instances.end()) {
    std::erase_if(instances, [&](const auto& entry) { return now_us - entry.second.sent_us > max_age_us_; });
    instances.emplace(trailer.instance_id, Seen{trailer.counter, trailer.sent_us});
    return std::nullopt;
  }
  if (trailer.counter <= seen->second.counter)
    return fmt::format("counter {} of sender {:016x}, already at {}", trailer.counter, trailer.instance_id,
                       seen->second.counter);
  seen->second = {trailer.counter, trailer.sent_us};
  return std::nullopt;
}

}  // namespace covtrack
