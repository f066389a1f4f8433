#include "subscriber_summary.hpp"

#include <fmt/format.h>

namespace covtrack::cli {

std::string subscriber_summary(const client::Subscriber& subscriber, const std::string& prefix) {
  std::string out;
  for (const auto& s : subscriber.streams())
    out += fmt::format("{}{}: received {}, lost {}, rejected {}, foreign {}, restarts {}\n", prefix, s.id.key(),
                       s.counters.received, s.counters.lost, s.counters.rejected, s.counters.foreign,
                       s.counters.restarts);
  out += fmt::format("{}rejected messages: {}\n", prefix, subscriber.rejections().summary());
  return out;
}

std::string receive_buffer_warning(const client::Subscriber& subscriber, const std::string& prefix) {
  const auto buffer = subscriber.receive_buffer();
  if (!buffer || buffer->note.empty()) return "";
  return fmt::format("{}warning: {}\n", prefix, buffer->note);
}

}  // namespace covtrack::cli
