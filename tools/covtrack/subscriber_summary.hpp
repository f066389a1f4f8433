#pragma once
// What a subscriber received, printed when `covtrack echo` and `covtrack view --live`
// end: one line per stream with its counters, and the messages it rejected by reason;
// and a warning when it starts if its receive buffer is smaller than asked for.
#include <string>

#include "covtrack/client/subscriber.hpp"

namespace covtrack::cli {

// Lines, each starting with `prefix` ("covtrack echo: ").
std::string subscriber_summary(const client::Subscriber& subscriber, const std::string& prefix);

// A line saying the kernel capped the socket receive buffer (so bursts may be lost), or
// nothing; shown when a program starts listening.
std::string receive_buffer_warning(const client::Subscriber& subscriber, const std::string& prefix);

}  // namespace covtrack::cli
