#pragma once
// Records LCM traffic into a log: subscribe, then dispatch until told to stop. LCM's
// handle() cannot be interrupted, so the loop polls LCM's descriptor together with a
// stop descriptor (a signal handler's self-pipe, or a test's pipe).
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "covtrack/lcmlog/log_writer.hpp"
#include "covtrack/protocol/rejection_tally.hpp"
#include "covtrack/protocol/result.hpp"

namespace covtrack::lcmlog {

struct RecordSummary {
  std::uint64_t events = 0;
  std::uint64_t bytes = 0;  // written to the file, event headers included
  std::map<std::string, std::uint64_t> events_per_channel;
  double duration_s = 0;
  // Messages of covtrack channels that fail the wire checks (check_channel_message()):
  // recorded as they came, since a log is evidence, and counted here by reason.
  RejectionTally bad_messages;
  // Events whose receive stamp was earlier than the event before them: written with that
  // event's stamp instead, so the log is in timestamp order (AscendingStamps).
  std::uint64_t restamped = 0;
};

// Stamps that never go back: events are written in the order they are handled, and a
// log's readers (lcm-logplayer, replay, lcm-spy) expect their stamps to ascend. LCM's
// receive stamps (the kernel's SO_TIMESTAMP) do not always: the kernel turns stamping on a
// moment after the socket asks, and a datagram that arrived before is stamped when read,
// after later arrivals (seen on the first few events of a session). Such an event keeps
// its place and takes the stamp of the event before it.
class AscendingStamps {
 public:
  std::int64_t stamp(std::int64_t received_us) {
    if (any_ && received_us < last_us_) {
      ++restamped_;
      return last_us_;
    }
    any_ = true;
    return last_us_ = received_us;
  }
  std::uint64_t restamped() const { return restamped_; }

 private:
  bool any_ = false;
  std::int64_t last_us_ = 0;
  std::uint64_t restamped_ = 0;
};

// LCM's default per-subscription queue of 30 drops the newest message silently when
// the disk stalls for a moment; this many small messages is a few hundred MB at most.
inline constexpr int kRecordQueueCapacity = 1 << 20;

class Recorder {
 public:
  // Subscribes at once: messages published after this returns are recorded.
  static Result<std::unique_ptr<Recorder>> start(lcm::LCM& lcm, LogWriter& writer,
                                                 const std::string& channel_regex);
  ~Recorder();

  // Records until `stop_fd` is readable, `duration_s` has passed, or a write fails.
  // Messages LCM has already queued when told to stop are still written.
  Result<RecordSummary> run(int stop_fd, std::optional<double> duration_s);

 private:
  Recorder(lcm::LCM& lcm, LogWriter& writer) : lcm_(lcm), writer_(writer) {}
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  lcm::LCM& lcm_;
  LogWriter& writer_;
  lcm::Subscription* subscription_ = nullptr;
  RecordSummary summary_;
  std::optional<Error> write_error_;
  AscendingStamps stamps_;
};

}  // namespace covtrack::lcmlog
