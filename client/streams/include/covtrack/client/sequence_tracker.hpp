#pragma once
// Classifies the sequence numbers of one stream, so that `lost` counts only messages the
// network lost: a jump forward within a window is loss; anything else (a jump beyond it,
// a step back, a duplicate) is off the stream's track. Messages off the track are a
// second publisher's, a forger's or a duplicate ("foreign"), until a new track shows
// itself as the stream's by carrying on alone for kConfirm messages in a row, with
// nothing on the old track between them: then it was a restart (of the daemon, or after
// a loss longer than the window), and the stream follows it from that message on.
//
// A forged message far ahead (which once made `lost` jump by 6.7e17) is one foreign
// message; the stream's next message is in order. Of two publishers that go on
// together, the one first heard keeps the stream and the other's messages are foreign,
// unless the other sends kConfirm messages between two of the first's: then the stream
// follows it (a restart) and the first's become foreign.
#include <cstdint>

namespace covtrack::client {

class SequenceTracker {
 public:
  enum class Verdict {
    First,    // the stream's first message
    InOrder,  // the next number, or a jump forward within the window (see lost)
    Foreign,  // off the stream's track
    Restart,  // the stream now follows a new track, from this message on
  };
  struct Result {
    Verdict verdict;
    std::int64_t lost = 0;  // InOrder: numbers skipped
  };

  // How many messages in a row on a new track, with none on the old one, make a restart.
  static constexpr int kConfirm = 3;

  // `window`: the largest forward jump still counted as loss.
  explicit SequenceTracker(std::int64_t window) : window_(window) {}

  Result classify(std::int64_t sequence);

 private:
  // Whether `to` is 1 to window_ ahead of `from` (no overflow for any two int64).
  bool ahead_within_window(std::int64_t from, std::int64_t to) const;

  std::int64_t window_;
  bool started_ = false;
  std::int64_t last_ = 0;  // the stream's track
  // A second track: its last number and how many of its messages came in a row with
  // nothing on the stream's track between them.
  bool candidate_ = false;
  std::int64_t candidate_last_ = 0;
  int candidate_run_ = 0;
};

}  // namespace covtrack::client
