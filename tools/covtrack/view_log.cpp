#include "view_log.hpp"

#include <fmt/format.h>

#include <covtrack/pose_cov_t.hpp>

#include "covtrack/client/pose_validation.hpp"
#include "covtrack/protocol/channels.hpp"

namespace covtrack::cli {

Result<LogFollower> LogFollower::open(const std::string& path) {
  auto reader = lcmlog::LogReader::open(path);
  if (!reader) return std::unexpected(reader.error());
  LogFollower follower(std::move(*reader));
  follower.pending_ = follower.reader_.next();
  if (!follower.pending_) return fail(fmt::format("{}: no events in the log", path));
  follower.start_us_ = follower.pending_->timestamp_us;
  return follower;
}

void LogFollower::advance_to(std::int64_t log_time_us, client::TransformGraph& graph) {
  while (pending_ && pending_->timestamp_us <= log_time_us) {
    feed(*pending_, graph);
    pending_ = reader_.next();
  }
}

void LogFollower::feed(const lcmlog::LogEvent& event, client::TransformGraph& graph) {
  const auto stream = parse_pose_channel(event.channel);
  if (!stream) return;  // raw bytes, truth, heartbeats: not for the view
  pose_cov_t msg;
  const int size = static_cast<int>(event.payload.size());
  if (msg.decode(event.payload.data(), 0, size) != size || client::rejection_reason(msg)) {
    ++rejected_;
    return;
  }
  client::TrackedTransform t = client::to_tracked_transform(msg, event.timestamp_us);
  if (t.stream != *stream) {  // a message must name its own channel's stream
    ++rejected_;
    return;
  }
  latest_[t.stream.key()] = t;
  (void)graph.update(t.stream, t);  // streams the scene does not use are not in the graph
}

std::optional<client::TrackedTransform> LogFollower::latest(const StreamId& id) const {
  const auto it = latest_.find(id.key());
  if (it == latest_.end()) return std::nullopt;
  return it->second;
}

}  // namespace covtrack::cli
