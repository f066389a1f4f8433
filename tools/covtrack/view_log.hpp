#pragma once
// `covtrack view --log FILE`: the view follows a recorded session's time. Pose events up
// to the current log time are fed to the transform graph, so regions (and staleness)
// are what a live view showed then. Damaged events are skipped (LogReader resyncs);
// invalid pose messages are counted, never used.
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "covtrack/client/tracked_transform.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::cli {

class LogFollower {
 public:
  static Result<LogFollower> open(const std::string& path);

  // Feeds every pose event with timestamp <= log_time_us into the graph.
  void advance_to(std::int64_t log_time_us, client::TransformGraph& graph);

  std::int64_t start_us() const { return start_us_; }
  bool finished() const { return !pending_; }
  std::optional<client::TrackedTransform> latest(const StreamId& id) const;
  long rejected() const { return rejected_; }

 private:
  explicit LogFollower(lcmlog::LogReader reader) : reader_(std::move(reader)) {}
  void feed(const lcmlog::LogEvent& event, client::TransformGraph& graph);

  lcmlog::LogReader reader_;
  std::optional<lcmlog::LogEvent> pending_;  // the next event, not yet due
  std::int64_t start_us_ = 0;
  std::map<std::string, client::TrackedTransform> latest_;  // by stream key
  long rejected_ = 0;
};

}  // namespace covtrack::cli
