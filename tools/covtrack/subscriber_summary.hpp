#pragma once
// What a subscriber received, printed when `covtrack echo` and `covtrack view --live`
// end: one line per stream with its counters, and the messages it rejected by reason;
// with a key, what authentication refused; and a warning when it starts if its receive
// buffer is smaller than asked for. The --key-file option of the programs that subscribe.
#include <string>

#include <CLI/CLI.hpp>

#include "covtrack/client/subscriber.hpp"

namespace covtrack::cli {

// Lines, each starting with `prefix` ("covtrack echo: ").
std::string subscriber_summary(const client::Subscriber& subscriber, const std::string& prefix);

// With a key, one line: the key file, messages authenticated and refused by kind; else nothing.
std::string authentication_line(const client::Subscriber& subscriber);

// --key-file, into SubscriberOptions::key_file.
void add_key_file_option(CLI::App& command, std::string& key_file);

// A line saying the kernel capped the socket receive buffer (so bursts may be lost), or
// nothing; shown when a program starts listening.
std::string receive_buffer_warning(const client::Subscriber& subscriber, const std::string& prefix);

}  // namespace covtrack::cli
