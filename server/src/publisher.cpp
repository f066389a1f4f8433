#include "publisher.hpp"

#include <cerrno>
#include <cstring>

#include <spdlog/spdlog.h>

#include <covtrack/image_t.hpp>
#include <covtrack/pose_cov_t.hpp>
#include <covtrack/raw_bytes_t.hpp>
#include <covtrack/truth_pose_t.hpp>

#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/clock.hpp"

namespace covtrack::server {

std::int64_t Publisher::next_sequence(const std::string& channel) {
  return sequences_[channel]++;
}

template <typename Msg>
bool Publisher::send(const std::string& channel, const Msg& msg) {
  const int size = msg.getEncodedSize();
  buffer_.resize(static_cast<std::size_t>(size));
  if (msg.encode(buffer_.data(), 0, size) != size) return false;
  if (signer_) signer_->sign(channel, buffer_);
  errno = 0;
  const bool sent = lcm_.publish(channel, buffer_.data(), static_cast<unsigned>(buffer_.size())) == 0;
  log_send_outcome(sent, channel, errno);
  return sent;
}

void Publisher::log_send_outcome(bool sent, const std::string& channel, int error) {
  if (sent && unsent_ > 0) {
    const std::chrono::duration<double> lasted = std::chrono::steady_clock::now() - failing_since_;
    spdlog::info("covtrackd: publishing again; {} message(s) were not sent in the last {:.1f} s", unsent_,
                 lasted.count());
    unsent_ = 0;
  } else if (!sent && unsent_++ == 0) {
    failing_since_ = std::chrono::steady_clock::now();
    spdlog::warn("covtrackd: cannot publish on {} ({}): messages are lost until the network is back",
                 channel, error != 0 ? std::strerror(error) : "LCM gave no reason");
  }
}

bool Publisher::pose(const std::string& device, const PoseSample& s) {
  pose_cov_t msg;
  msg.measurement_time_us = s.measurement_time_us;
  msg.device = device;
  msg.sensor = s.sensor;
  msg.parent_frame = s.parent_frame;
  msg.child_frame = s.child_frame;
  set_pose(msg, s.T_parent_child, s.covariance);
  msg.status = static_cast<std::int8_t>(s.status);
  const std::string channel = pose_channel(device, s.sensor);
  bool sent = false;
  {
    std::lock_guard lock(mutex_);
    msg.sequence = next_sequence(channel);
    msg.publish_time_us = now_us();
    sent = send(channel, msg);
  }
  if (tap_) tap_(device, s);
  return sent;
}

bool Publisher::truth(const std::string& device, const TruthSample& s) {
  truth_pose_t msg;
  msg.measurement_time_us = s.measurement_time_us;
  msg.device = device;
  msg.sensor = s.sensor;
  msg.parent_frame = s.parent_frame;
  msg.child_frame = s.child_frame;
  set_pose(msg, s.T_parent_child);
  const std::string channel = truth_channel(device, s.sensor);
  std::lock_guard lock(mutex_);
  msg.sequence = next_sequence(channel);
  return send(channel, msg);
}

bool Publisher::raw(const std::string& device, ByteDirection direction, const std::uint8_t* data,
                    std::size_t size) {
  raw_bytes_t msg;
  msg.time_us = now_us();
  msg.device = device;
  msg.direction = static_cast<std::int8_t>(direction);
  msg.length = static_cast<std::int32_t>(size);
  msg.data.assign(data, data + size);
  std::lock_guard lock(mutex_);
  return send(raw_channel(device), msg);
}

bool Publisher::image(const std::string& device, const ImageSample& s) {
  image_t msg;
  msg.measurement_time_us = s.measurement_time_us;
  msg.device = device;
  msg.width = s.width;
  msg.height = s.height;
  msg.encoding = s.encoding;
  msg.size = static_cast<std::int32_t>(s.bytes.size());
  msg.data = s.bytes;
  std::lock_guard lock(mutex_);
  return send(image_channel(device), msg);
}

bool Publisher::status(const device_status_t& status) {
  std::lock_guard lock(mutex_);
  return send(status_channel(status.device), status);
}

}  // namespace covtrack::server
