#include "covtrack/lcmlog/channel_filter.hpp"

namespace covtrack::lcmlog {

Result<ChannelFilter> ChannelFilter::create(const std::string& pattern) {
  try {
    ChannelFilter filter(pattern, std::regex(pattern, std::regex::ECMAScript));
    filter.match_all_ = pattern == ".*";
    return filter;
  } catch (const std::regex_error& e) {
    return fail("channel regex '" + pattern + "' is invalid: " + e.what());
  }
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
