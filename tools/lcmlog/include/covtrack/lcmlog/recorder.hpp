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
};

}  // namespace covtrack::lcmlog
