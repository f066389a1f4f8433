#include "covtrack/protocol/channel_pattern.hpp"

namespace covtrack {

Result<std::regex> compile_channel_pattern(const std::string& pattern) {
  try {
    return std::regex(pattern, std::regex::extended | std::regex::optimize);
  } catch (const std::regex_error& e) {
    return fail("pattern '" + pattern + "' is not a POSIX extended regular expression: " + e.what());
  }
}

}  // namespace covtrack
