#pragma once
// What a subscriber received, printed when `covtrack echo` and `covtrack view --live`
// end: one line per stream with its counters, and the messages it rejected by reason.
#include <string>

#include "covtrack/client/subscriber.hpp"

namespace covtrack::cli {

// Lines, each starting with `prefix` ("covtrack echo: ").
std::string subscriber_summary(const client::Subscriber& subscriber, const std::string& prefix);

}  // namespace covtrack::cli
