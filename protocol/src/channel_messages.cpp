#include "covtrack/protocol/channel_messages.hpp"

#include <cmath>

#include <fmt/format.h>

#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/wire_text.hpp"
#include "rejection.hpp"

namespace covtrack {
namespace {

constexpr std::int64_t kMinHeartbeatPeriodUs = 1'000;
constexpr std::int64_t kMaxHeartbeatPeriodUs = 3'600'000'000;

std::unexpected<WireRejection> bad_channel(std::string_view channel, std::string_view shape) {
  return reject(WireFault::BadChannel, fmt::format("channel '{}' is not {} with names of 1-{} characters "
                                                   "of A-Z a-z 0-9 _ -", printable(channel), shape, kMaxNameLength));
}

// Decodes a message of a channel `prefix<device>[/<sensor>]` and checks that its names are the channel's.
template <typename Msg>
Decoded<Msg> decode_named(std::string_view channel, std::span<const std::byte> bytes, std::string_view prefix,
                          bool with_sensor) {
  std::optional<std::string> expected;
  if (with_sensor) {
    if (const auto id = parse_stream_channel(channel, prefix)) expected = id->key();
  } else {
    expected = parse_device_channel(channel, prefix);
  }
  if (!expected) return bad_channel(channel, fmt::format("{}<device>{}", prefix, with_sensor ? "/<sensor>" : ""));
  auto msg = decode_message<Msg>(bytes);
  if (!msg) return msg;
  std::string named = msg->device;
  if constexpr (requires { msg->sensor; }) named += "/" + msg->sensor;
  if (named != *expected)
    return reject(WireFault::WrongChannel, fmt::format("the message names '{}', its channel '{}'", named, *expected));
  return msg;
}

}  // namespace

Decoded<pose_cov_t> decode_pose(std::string_view channel, std::span<const std::byte> bytes) {
  return decode_named<pose_cov_t>(channel, bytes, kPosePrefix, true);
}

Decoded<device_status_t> decode_status(std::string_view channel, std::span<const std::byte> bytes) {
  auto msg = decode_named<device_status_t>(channel, bytes, kStatusPrefix, false);
  if (!msg) return msg;
  if (msg->state < device_status_t::STATE_STARTING || msg->state > device_status_t::STATE_STOPPED)
    return reject(WireFault::BadValue, fmt::format("unknown state {}", msg->state));
  if (!std::isfinite(msg->rate_hz) || msg->rate_hz < 0)
    return reject(WireFault::BadValue, fmt::format("rate_hz {} is not a rate", msg->rate_hz));
  if (msg->heartbeat_period_us < kMinHeartbeatPeriodUs || msg->heartbeat_period_us > kMaxHeartbeatPeriodUs)
    return reject(WireFault::BadValue, fmt::format("heartbeat_period_us {} is outside {}-{}", msg->heartbeat_period_us,
                                                   kMinHeartbeatPeriodUs, kMaxHeartbeatPeriodUs));
  return msg;
}

Decoded<device_claim_t> decode_claim(std::string_view channel, std::span<const std::byte> bytes) {
  auto msg = decode_named<device_claim_t>(channel, bytes, kClaimPrefix, false);
  if (!msg) return msg;
  if (msg->stage != device_claim_t::STAGE_CLAIMING && msg->stage != device_claim_t::STAGE_HOLDING)
    return reject(WireFault::BadValue, fmt::format("unknown stage {}", msg->stage));
  return msg;
}

Decoded<image_t> decode_image(std::string_view channel, std::span<const std::byte> bytes) {
  return decode_named<image_t>(channel, bytes, kImagePrefix, false);
}

std::optional<WireRejection> check_channel_message(std::string_view channel, std::span<const std::byte> bytes) {
  const auto verdict = [](const auto& decoded) -> std::optional<WireRejection> {
    if (decoded) return std::nullopt;
    return decoded.error();
  };
  if (channel.starts_with(kPosePrefix)) return verdict(decode_pose(channel, bytes));
  if (channel.starts_with(kStatusPrefix)) return verdict(decode_status(channel, bytes));
  if (channel.starts_with(kImagePrefix)) return verdict(decode_image(channel, bytes));
  if (channel.starts_with(kClaimPrefix)) return verdict(decode_claim(channel, bytes));
  if (channel.starts_with(kTruthPrefix))
    return verdict(decode_named<truth_pose_t>(channel, bytes, kTruthPrefix, true));
  if (channel.starts_with(kRawPrefix)) return verdict(decode_named<raw_bytes_t>(channel, bytes, kRawPrefix, false));
  return std::nullopt;
}

}  // namespace covtrack
