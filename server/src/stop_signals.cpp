#include "stop_signals.hpp"

#include <pthread.h>
#include <unistd.h>

#include <cerrno>

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
  sigaddset(&stop_signals, kNothingLeftSignal);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  return stop_signals;
}

int wait_for_stop_signal(const sigset_t& stop_signals) {
  int signal = 0;
  while (sigwait(&stop_signals, &signal) != 0) {}
  return signal;
}

std::optional<int> wait_for_stop_signal(const sigset_t& stop_signals, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(end - std::chrono::steady_clock::now());
    if (left.count() <= 0) return std::nullopt;
    const timespec ts{static_cast<time_t>(left.count() / 1'000'000'000), static_cast<long>(left.count() % 1'000'000'000)};
    const int signal = sigtimedwait(&stop_signals, nullptr, &ts);
    if (signal > 0) return signal;
    if (errno == EAGAIN) return std::nullopt;  // EINTR: another signal's handler ran; wait on
  }
}

void signal_nothing_left() { ::kill(::getpid(), kNothingLeftSignal); }

}  // namespace covtrack::server
