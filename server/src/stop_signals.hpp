#pragma once
// SIGINT and SIGTERM, handled from the daemon's first instruction to its last.
//
// Until the devices start, a stop signal ends the daemon at once: there is nothing to
// stop yet, and reading the config (a pipe nobody writes, a slow disk) may block. It
// says so on stderr and ends by the signal itself (status 130 or 143 in a shell).
// Before the first thread starts, the signals are blocked, so that every thread
// inherits the mask and only wait_for_stop_signal() receives them.
#include <chrono>
#include <csignal>
#include <optional>

namespace covtrack::server {

// The first call in main().
void end_at_once_on_stop_signal();
// Before any thread exists; a signal that comes from then on waits for the next call.
// The set also holds kNothingLeftSignal.
sigset_t block_stop_signals();
// Returns the signal that came (SIGINT, SIGTERM or kNothingLeftSignal).
int wait_for_stop_signal(const sigset_t& stop_signals);
// The same, waiting at most `timeout`: nothing when no signal came.
std::optional<int> wait_for_stop_signal(const sigset_t& stop_signals, std::chrono::milliseconds timeout);

// What a daemon thread sends the process when every device has been given up to other
// daemons: the main thread then stops the daemon (exit code 1).
inline constexpr int kNothingLeftSignal = SIGUSR1;
void signal_nothing_left();

}  // namespace covtrack::server
