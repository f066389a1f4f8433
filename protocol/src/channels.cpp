#include "covtrack/protocol/channels.hpp"

#include <algorithm>

namespace covtrack {

bool is_valid_name(std::string_view name) {
  return !name.empty() && name.size() <= kMaxNameLength &&
         std::all_of(name.begin(), name.end(), [](char ch) {
           return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                  (ch >= '0' && ch <= '9') || ch == '_' || ch == '-';
         });
}

namespace {
std::string join(std::string_view prefix, std::string_view a, std::string_view b = {}) {
  std::string out(prefix);
  out += a;
  if (!b.empty()) {
    out += '/';
    out += b;
  }
  return out;
}
}  // namespace

std::string pose_channel(std::string_view d, std::string_view s) { return join(kPosePrefix, d, s); }
std::string truth_channel(std::string_view d, std::string_view s) { return join(kTruthPrefix, d, s); }
std::string status_channel(std::string_view d) { return join(kStatusPrefix, d); }
std::string raw_channel(std::string_view d) { return join(kRawPrefix, d); }
std::string image_channel(std::string_view d) { return join(kImagePrefix, d); }
std::string claim_channel(std::string_view d) { return join(kClaimPrefix, d); }

std::optional<StreamId> parse_stream_channel(std::string_view channel, std::string_view prefix) {
  if (!channel.starts_with(prefix)) return std::nullopt;
  channel.remove_prefix(prefix.size());
  const auto slash = channel.find('/');
  if (slash == std::string_view::npos) return std::nullopt;
  StreamId id{std::string(channel.substr(0, slash)), std::string(channel.substr(slash + 1))};
  if (!is_valid_name(id.device) || !is_valid_name(id.sensor)) return std::nullopt;
  return id;
}

std::optional<std::string> parse_device_channel(std::string_view channel, std::string_view prefix) {
  if (!channel.starts_with(prefix)) return std::nullopt;
  channel.remove_prefix(prefix.size());
  if (!is_valid_name(channel)) return std::nullopt;
  return std::string(channel);
}

std::optional<StreamId> parse_pose_channel(std::string_view channel) {
  return parse_stream_channel(channel, kPosePrefix);
}

}  // namespace covtrack
