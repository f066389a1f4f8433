#pragma once
// One pattern syntax for everything that picks streams or channels: a POSIX extended
// regular expression (the dialect LCM's own subscriptions use, regcomp's), matched against
// the whole name. What the name is depends on the tool: the Subscriber, `covtrack echo` and
// Python's Subscriber match "device/sensor"; `covtrack record`, `replay` and the log
// library match whole LCM channel names ("covtrack/pose/rig/head"), since a log holds
// every channel on the bus.
#include <regex>
#include <string>

#include "covtrack/protocol/result.hpp"

namespace covtrack {

// Fails with "pattern '<pattern>' is not a POSIX extended regular expression: <why>".
Result<std::regex> compile_channel_pattern(const std::string& pattern);

}  // namespace covtrack
