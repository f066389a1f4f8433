#pragma once
// LCM channel naming (protocol/README.md, "Channels").
#include <optional>
#include <string>
#include <string_view>

namespace covtrack {

inline constexpr std::string_view kPosePrefix = "covtrack/pose/";
inline constexpr std::string_view kTruthPrefix = "covtrack/truth/";
inline constexpr std::string_view kStatusPrefix = "covtrack/status/";
inline constexpr std::string_view kRawPrefix = "covtrack/raw/";
inline constexpr std::string_view kImagePrefix = "covtrack/image/";
// Between daemons only: who publishes a device (device_claim_t).
inline constexpr std::string_view kClaimPrefix = "covtrack/claim/";

// LCM limits channel names to 63 characters; with the longest prefix and a '/',
// device and sensor names of at most 23 characters each always fit.
inline constexpr std::size_t kMaxNameLength = 23;

// Device and sensor names: 1-23 characters of [A-Za-z0-9_-].
bool is_valid_name(std::string_view name);

std::string pose_channel(std::string_view device, std::string_view sensor);
std::string truth_channel(std::string_view device, std::string_view sensor);
std::string status_channel(std::string_view device);
std::string raw_channel(std::string_view device);
std::string image_channel(std::string_view device);
std::string claim_channel(std::string_view device);

struct StreamId {
  std::string device;
  std::string sensor;
  std::string key() const { return device + "/" + sensor; }
  bool operator==(const StreamId&) const = default;
};

// The stream of a pose channel, or nothing if the channel is not a pose channel.
std::optional<StreamId> parse_pose_channel(std::string_view channel);
// The stream of a channel `prefix<device>/<sensor>` (pose, truth), or nothing.
std::optional<StreamId> parse_stream_channel(std::string_view channel, std::string_view prefix);
// The device of a channel `prefix<device>` (status, raw, image, claim), or nothing.
std::optional<std::string> parse_device_channel(std::string_view channel, std::string_view prefix);

}  // namespace covtrack
