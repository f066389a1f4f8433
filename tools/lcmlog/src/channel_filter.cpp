#include "covtrack/lcmlog/channel_filter.hpp"

#include "covtrack/protocol/channel_pattern.hpp"

namespace covtrack::lcmlog {

Result<ChannelFilter> ChannelFilter::create(const std::string& pattern) {
  auto regex = compile_channel_pattern(pattern);
  if (!regex) return std::unexpected(regex.error());
  ChannelFilter filter(pattern, std::move(*regex));
  filter.match_all_ = pattern == ".*";
  return filter;
}

bool ChannelFilter::matches(std::string_view channel) {
  if (match_all_) return true;
  // A short string copy per lookup costs far less than the publish that follows, and
  // only happens when a filter other than ".*" is given.
  const std::string key(channel);
  if (auto it = verdicts_.find(key); it != verdicts_.end()) return it->second;
  const bool verdict = std::regex_match(key, regex_);
  verdicts_.emplace(key, verdict);
  return verdict;
}

}  // namespace covtrack::lcmlog
