#include "view_log.hpp"

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "covtrack/client/pose_validation.hpp"
#include "covtrack/protocol/channel_messages.hpp"
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

void LogFollower::advance_to(std::int64_t log_time_us, client::TransformGraph& graph, FrameMismatches& mismatches) {
  while (pending_ && pending_->timestamp_us <= log_time_us) {
    feed(*pending_, graph, mismatches);
    pending_ = reader_.next();
  }
}

void LogFollower::feed(const lcmlog::LogEvent& event, client::TransformGraph& graph, FrameMismatches& mismatches) {
  if (event.channel.starts_with(kImagePrefix)) return keep_image(event);
  if (!event.channel.starts_with(kPosePrefix)) return;  // raw bytes, truth, heartbeats: not for the view
  const std::string channel(event.channel);
  const auto msg = decode_pose(channel, event.payload);
  if (!msg) return rejections_.add(to_string(msg.error().fault), channel, msg.error().describe());
  if (auto invalid = client::rejection_reason(*msg)) return rejections_.add("invalid pose", channel, *invalid);
  client::TrackedTransform t = client::to_tracked_transform(*msg, event.timestamp_us);
  latest_[t.stream.key()] = t;
  mismatches.update(graph, t);
}

// Kept encoded: most frames of a fast replay are overtaken before they are drawn.
void LogFollower::keep_image(const lcmlog::LogEvent& event) {
  const std::string_view device = event.channel.substr(kImagePrefix.size());
  if (image_device_.empty()) image_device_ = device;
  if (device != image_device_) return;
  undrawn_.push_back({{event.payload.begin(), event.payload.end()}, event.timestamp_us});
  if (undrawn_.size() > kKeptImages) undrawn_.pop_front();
}

const cv::Mat& LogFollower::image(std::string& warning) {
  while (!undrawn_.empty()) {
    const EncodedImage newest = std::move(undrawn_.back());
    undrawn_.pop_back();
    if (decode_frame(newest.payload, newest.time_us, warning)) {
      undrawn_.clear();  // older than what is now shown
      break;
    }
  }
  return image_;
}

bool LogFollower::decode_frame(const std::vector<std::byte>& payload, std::int64_t time_us,
                               std::string& warning) {
  const auto corrupt = [&](const std::string& why) {
    ++corrupt_images_;
    warning = fmt::format("image from '{}' at log time {} us skipped: {}", image_device_, time_us, why);
    return false;
  };
  const auto message = decode_image(image_channel(image_device_), payload);
  if (!message) return corrupt(message.error().describe());
  const image_t& msg = *message;
  if (msg.encoding != "jpeg" && msg.encoding != "png")
    return corrupt(fmt::format("encoding '{}' is neither jpeg nor png", msg.encoding));
  cv::Mat decoded;
  try {
    decoded = cv::imdecode(msg.data, cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {  // some codecs throw on damaged data instead of failing
    return corrupt(e.what());
  }
  if (decoded.empty()) return corrupt(fmt::format("{} data does not decode", msg.encoding));
  if (decoded.cols != msg.width || decoded.rows != msg.height)
    return corrupt(fmt::format("decodes to {}x{}, the message says {}x{}", decoded.cols, decoded.rows,
                               msg.width, msg.height));
  image_ = decoded;
  return true;
}

std::optional<client::TrackedTransform> LogFollower::latest(const StreamId& id) const {
  const auto it = latest_.find(id.key());
  if (it == latest_.end()) return std::nullopt;
  return it->second;
}

}  // namespace covtrack::cli
