#include "covtrack/lcmlog/replayer.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include "covtrack/lcmlog/channel_filter.hpp"
#include "covtrack/protocol/channel_messages.hpp"

namespace covtrack::lcmlog {
namespace {

using Clock = std::chrono::steady_clock;
constexpr std::uint64_t kProgressEveryEvents = 4096;
// Waits are cut into slices so a stop request is seen within this time.
constexpr auto kMaxWaitSlice = std::chrono::milliseconds(50);

}  // namespace

Result<ReplaySummary> replay(LogReader& reader, lcm::LCM& lcm, const ReplayOptions& options,
                             const std::atomic<bool>& stop,
                             const std::function<void(const ReplayProgress&)>& progress) {
  if (options.speed < 0) return fail("--speed must be >= 0 (0: as fast as possible)");
  if (options.start_s < 0) return fail("--start must be >= 0 seconds");
  auto filter = ChannelFilter::create(options.channels);
  if (!filter) return std::unexpected(filter.error());

  ReplaySummary summary;
  std::string channel;  // NUL-terminated copy for lcm_publish, reused to avoid allocations
  lcm_t* raw_lcm = lcm.getUnderlyingLCM();
  std::optional<std::int64_t> log_start_us;  // timestamp of the log's first event

  while (!stop.load(std::memory_order_relaxed)) {
    std::uint64_t published_this_pass = 0;
    std::optional<std::int64_t> pace_base_us;  // timestamp published at pass_started
    Clock::time_point pass_started;
    double log_time_s = 0;
    auto report = [&] {
      if (progress)
        progress({summary.events_published, log_time_s, reader.offset(), reader.size()});
    };

    bool stopped_in_pass = false;
    while (auto event = reader.next()) {
      if ((stopped_in_pass = stop.load(std::memory_order_relaxed))) break;
      if (!log_start_us) log_start_us = event->timestamp_us;
      // Times relative to the first event, in double: a damaged log's timestamps can be
      // anything, and int64 differences of such overflow. An event timed before the first
      // (recorders stamp in the order they receive, which is not always time order) is
      // published like the others, at once, as lcm-logplayer does; --start skips only
      // events timed within its first seconds.
      const double since_start_s = 1e-6 * (static_cast<double>(event->timestamp_us) - static_cast<double>(*log_start_us));
      if (options.start_s > 0 && since_start_s < options.start_s) continue;
      if (!filter->matches(event->channel)) continue;

      if (options.speed > 0) {
        if (!pace_base_us) {
          pace_base_us = event->timestamp_us;
          pass_started = Clock::now();
        }
        // Clamped to a day ahead: a damaged timestamp must not overflow the clock's type.
        const double wait_s = std::clamp(
            1e-6 * (static_cast<double>(event->timestamp_us) - static_cast<double>(*pace_base_us)) / options.speed,
            0.0, 86400.0);
        const auto due = pass_started + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait_s));
        for (auto now = Clock::now(); now < due && !stop.load(); now = Clock::now()) {
          report();
          std::this_thread::sleep_until(std::min(due, now + kMaxWaitSlice));
        }
        if ((stopped_in_pass = stop.load())) break;
      }

      channel.assign(event->channel);
      if (summary.passes == 0)
        if (const auto bad = check_channel_message(channel, event->payload))
          summary.bad_messages.add(to_string(bad->fault), channel, bad->describe());
      if (lcm_publish(raw_lcm, channel.c_str(), event->payload.data(),
                      static_cast<unsigned int>(event->payload.size())) != 0)
        return fail("publishing '" + channel + "' failed (event at byte offset " +
                    std::to_string(event->offset) + ")");
      ++summary.events_published;
      ++published_this_pass;
      summary.payload_bytes += event->payload.size();
      log_time_s = std::max(log_time_s, since_start_s);
      if (summary.events_published % kProgressEveryEvents == 0) report();
    }
    report();
    if (summary.passes == 0) summary.damage = reader.damage();
    if (stopped_in_pass) break;
    ++summary.passes;
    if (stop.load()) break;
    // A pass that published nothing would make --loop spin forever.
    if (!options.loop || published_this_pass == 0) break;
    reader.rewind();
  }
  summary.stopped = stop.load();
  return summary;
}

}  // namespace covtrack::lcmlog
