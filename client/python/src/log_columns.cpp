#include "log_columns.hpp"

#include "covtrack/client/pose_validation.hpp"
#include "covtrack/protocol/channel_messages.hpp"

namespace covtrack::python {

Eigen::Vector4d quaternion_wxyz(const Pose& T) {
  Eigen::Quaterniond q(T.linear());
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return {q.w(), q.x(), q.y(), q.z()};
}

void TruthColumns::add_pose(const Pose& T) {
  const Vec3 p = T.translation();
  position_m.insert(position_m.end(), p.data(), p.data() + 3);
  const Eigen::Vector4d q = python::quaternion_wxyz(T);
  quaternion_wxyz.insert(quaternion_wxyz.end(), q.data(), q.data() + 4);
}

namespace {

template <typename Columns, typename Message>
Columns& stream_of(std::map<std::string, Columns>& streams, const Message& msg) {
  const StreamId id{msg.device, msg.sensor};
  auto [it, added] = streams.try_emplace(id.key());
  if (added) {
    it->second.id = id;
    it->second.parent_frame = msg.parent_frame;
    it->second.child_frame = msg.child_frame;
  }
  return it->second;
}

void add_pose_event(LogColumns& log, const lcmlog::LogEvent& event, const std::string& channel) {
  const auto msg = decode_pose(channel, event.payload);
  if (!msg) return log.rejections.add(to_string(msg.error().fault), channel, msg.error().describe());
  if (auto invalid = client::rejection_reason(*msg)) return log.rejections.add("invalid pose", channel, *invalid);
  // The client's reading of a message: BODY covariance, a LOST one's made infinite.
  const client::TrackedTransform t = client::to_tracked_transform(*msg, event.timestamp_us);
  PoseColumns& s = stream_of(log.poses, *msg);
  s.log_time_us.push_back(event.timestamp_us);
  s.measurement_time_us.push_back(t.measurement_time_us);
  s.publish_time_us.push_back(t.publish_time_us);
  s.sequence.push_back(t.sequence);
  s.add_pose(t.T_parent_child);
  const Eigen::Matrix<double, 6, 6, Eigen::RowMajor> c = t.covariance;
  s.covariance.insert(s.covariance.end(), c.data(), c.data() + 36);
  s.status.push_back(static_cast<std::int8_t>(t.status));
}

void add_truth_event(LogColumns& log, const lcmlog::LogEvent& event, const std::string& channel) {
  if (auto why = check_channel_message(channel, event.payload))
    return log.rejections.add(to_string(why->fault), channel, why->describe());
  const auto msg = decode_message<truth_pose_t>(event.payload);  // passed the same checks
  if (!msg) return log.rejections.add(to_string(msg.error().fault), channel, msg.error().describe());
  TruthColumns& s = stream_of(log.truth, *msg);
  s.log_time_us.push_back(event.timestamp_us);
  s.measurement_time_us.push_back(msg->measurement_time_us);
  s.sequence.push_back(msg->sequence);
  s.add_pose(pose_of(*msg));
}

}  // namespace

Result<LogColumns> read_log_columns(const std::string& path) {
  auto reader = lcmlog::LogReader::open(path);
  if (!reader) return std::unexpected(reader.error());
  LogColumns log;
  while (const auto event = reader->next()) {
    ++log.events;
    const std::string channel(event->channel);
    if (channel.starts_with(kPosePrefix))
      add_pose_event(log, *event, channel);
    else if (channel.starts_with(kTruthPrefix))
      add_truth_event(log, *event, channel);
  }
  log.damage = reader->damage();
  return log;
}

}  // namespace covtrack::python
