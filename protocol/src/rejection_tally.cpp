#include "covtrack/protocol/rejection_tally.hpp"

#include <fmt/format.h>

#include "covtrack/protocol/wire_text.hpp"

namespace covtrack {

void RejectionTally::add(const std::string& reason, const std::string& channel, const std::string& description) {
  ++total;
  ++by_reason[reason];
  last = printable(channel) + ": " + description;
}

std::string RejectionTally::summary() const {
  if (total == 0) return "0";
  std::string reasons;
  for (const auto& [reason, count] : by_reason)
    reasons += fmt::format("{}{} {}", reasons.empty() ? "" : ", ", reason, count);
  return fmt::format("{} ({}); last: {}", total, reasons, last);
}

}  // namespace covtrack
