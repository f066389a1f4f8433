#pragma once
// Publishes the events of a log with their original timing scaled by 1/speed.
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/protocol/rejection_tally.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::lcmlog {

struct ReplayOptions {
  double speed = 1.0;  // 0: as fast as possible
  bool loop = false;   // start again at the end, until stopped
  double start_s = 0;  // skip events in the first start_s seconds of the log
  std::string channels = ".*";
};

struct ReplayProgress {
  std::uint64_t events_published;
  double log_time_s;  // of the last published event, since the first event of the log
  std::uint64_t offset, size;  // bytes read so far in this pass, and the file size
};

struct ReplaySummary {
  std::uint64_t events_published = 0;  // over all passes
  std::uint64_t payload_bytes = 0;
  std::uint64_t passes = 0;             // completed passes
  std::vector<LogDamage> damage;        // found in the first pass
  // Messages of covtrack channels in the first pass that fail the wire checks
  // (check_channel_message()): published as they are, since a replay reproduces what
  // was on the wire, and counted here by reason.
  RejectionTally bad_messages;
  bool stopped = false;                 // `stop` was set before the end
};

// Replays `reader` from its current position. Events are published in file order, which
// is the order the recorder received them in; each is held back until
// start + (its timestamp - first timestamp) / speed on one steady clock, so sleeping
// never accumulates drift, and a timestamp that goes backwards is published at once.
// `progress`, if set, is called every few thousand events and while waiting.
Result<ReplaySummary> replay(LogReader& reader, lcm::LCM& lcm, const ReplayOptions& options,
                             const std::atomic<bool>& stop,
                             const std::function<void(const ReplayProgress&)>& progress = {});

}  // namespace covtrack::lcmlog
