#pragma once
// SIGINT and SIGTERM, handled from the daemon's first instruction to its last.
//
// Until the devices start, a stop signal ends the daemon at once: there is nothing to
// stop yet, and reading the config (a pipe nobody writes, a slow disk) may block. It
// says so on stderr and ends by the signal itself (status 130 or 143 in a shell).
// Before the first thread starts, the signals are blocked, so that every thread
// inherits the mask and only wait_for_stop_signal() receives them.
#include <csignal>

namespace covtrack::server {

// The first call in main().
void end_at_once_on_stop_signal();
// Before any thread exists; a signal that comes from then on waits for the next call.
sigset_t block_stop_signals();
// Returns the signal that came (SIGINT or SIGTERM).
int wait_for_stop_signal(const sigset_t& stop_signals);

}  // namespace covtrack::server
