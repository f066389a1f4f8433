#include "stop_signals.hpp"

#include <pthread.h>
#include <unistd.h>

namespace covtrack::server {
namespace {

template <std::size_t N>
void say(const char (&text)[N]) {
  [[maybe_unused]] const auto written = ::write(STDERR_FILENO, text, N - 1);
}

// Only async-signal-safe calls: write, raise. SA_RESETHAND has already restored the
// default action, so the raised signal ends the process (at once, or when this returns).
extern "C" void end_now(int signal) {
  if (signal == SIGINT) say("covtrackd: SIGINT before the devices started; nothing was started\n");
  else say("covtrackd: SIGTERM before the devices started; nothing was started\n");
  ::raise(signal);
}

}  // namespace

void end_at_once_on_stop_signal() {
  struct sigaction action {};
  action.sa_handler = end_now;
  action.sa_flags = SA_RESETHAND;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

sigset_t block_stop_signals() {
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  return stop_signals;
}

int wait_for_stop_signal(const sigset_t& stop_signals) {
  int signal = 0;
  while (sigwait(&stop_signals, &signal) != 0) {}
  return signal;
}

}  // namespace covtrack::server
