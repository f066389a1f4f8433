#pragma once
// Counts rejected messages by reason, and keeps the latest one's description: what every
// covtrack program that receives messages reports about the ones it refused.
#include <cstdint>
#include <map>
#include <string>

namespace covtrack {

struct RejectionTally {
  std::int64_t total = 0;
  std::map<std::string, std::int64_t> by_reason;  // a short reason: "bad length", "invalid pose", ...
  std::string last;                               // channel and full description of the latest

  // The channel came from the wire too: it is kept in printable() form.
  void add(const std::string& reason, const std::string& channel, const std::string& description);
  // "3 (bad length 2, wrong type 1); last: covtrack/pose/a/b: bad length: ..."
  std::string summary() const;
};

}  // namespace covtrack
