// Reads an LCM log (covtrack record, lcm-logger) into poses, as a client would have
// received them: per stream the number of poses by status and the last one.
//   read_log session.lcm
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include <covtrack/client/pose_validation.hpp>
#include <covtrack/lcmlog/log_reader.hpp>
#include <covtrack/protocol/channel_messages.hpp>

struct StreamSummary {
  int count[3] = {0, 0, 0};  // by TrackingStatus: OK, DEGRADED, LOST
  covtrack::client::TrackedTransform last;
};

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: read_log LOG\n");
    return 2;
  }
  auto log = covtrack::lcmlog::LogReader::open(argv[1]);
  if (!log) {
    std::fprintf(stderr, "read_log: %s\n", log.error().message.c_str());
    return 1;
  }
  std::map<std::string, StreamSummary> streams;
  int rejected = 0;
  while (auto event = log->next()) {
    const std::string channel(event->channel);
    if (!channel.starts_with(covtrack::kPosePrefix)) continue;
    // Nothing in a file is trusted: decode with covtrack's checks, then the client's.
    const auto msg = covtrack::decode_pose(channel, event->payload);
    if (!msg || covtrack::client::rejection_reason(*msg)) {
      ++rejected;
      continue;
    }
    const auto pose = covtrack::client::to_tracked_transform(*msg, event->timestamp_us);
    auto& s = streams[pose.stream.key()];
    ++s.count[static_cast<int>(pose.status)];
    s.last = pose;
  }
  for (const auto& [key, s] : streams) {
    const auto& p = s.last.T_parent_child.translation();
    std::printf("%s: %d ok %d degraded %d lost; last at %lld us: [%.6f %.6f %.6f] m in %s",
                key.c_str(), s.count[0], s.count[1], s.count[2],
                static_cast<long long>(s.last.measurement_time_us), p.x(), p.y(), p.z(),
                s.last.parent_frame.c_str());
    if (!s.last.lost()) std::printf(", sigma x %.6f m", std::sqrt(s.last.covariance(0, 0)));
    std::printf("\n");
  }
  std::printf("rejected %d, damaged ranges %zu\n", rejected, log->damage().size());
}
