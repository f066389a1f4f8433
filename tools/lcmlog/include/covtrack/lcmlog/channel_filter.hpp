#pragma once
// Which channels a command handles: a pattern over whole channel names
// (protocol/channel_pattern.hpp: POSIX extended, as LCM's own subscribe(); "covtrack/pose/.*", not "pose").
#include <regex>
#include <string>
#include <string_view>
#include <unordered_map>

#include "covtrack/protocol/result.hpp"

namespace covtrack::lcmlog {

class ChannelFilter {
 public:
  static Result<ChannelFilter> create(const std::string& regex);

  // A log has few distinct channels and up to millions of events: the verdict per
  // channel is cached so std::regex runs once per channel, not once per event.
  bool matches(std::string_view channel);

  const std::string& pattern() const { return pattern_; }

 private:
  ChannelFilter(std::string pattern, std::regex regex)
      : pattern_(std::move(pattern)), regex_(std::move(regex)) {}

  std::string pattern_;
  std::regex regex_;
  bool match_all_ = false;
  std::unordered_map<std::string, bool> verdicts_;
};

}  // namespace covtrack::lcmlog
