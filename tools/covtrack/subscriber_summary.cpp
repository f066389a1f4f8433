#include "subscriber_summary.hpp"

#include <fmt/format.h>

namespace covtrack::cli {

std::string subscriber_summary(const client::Subscriber& subscriber, const std::string& prefix) {
  std::string out;
  for (const auto& s : subscriber.streams())
    out += fmt::format("{}{}: received {}, lost {}, rejected {}, foreign {}, restarts {}\n", prefix, s.id.key(),
                       s.counters.received, s.counters.lost, s.counters.rejected, s.counters.foreign,
                       s.counters.restarts);
  if (const std::string auth = authentication_line(subscriber); !auth.empty()) out += prefix + auth;
  out += fmt::format("{}rejected messages: {}\n", prefix, subscriber.rejections().summary());
  return out;
}

std::string authentication_line(const client::Subscriber& subscriber) {
  const auto auth = subscriber.authentication();
  if (!auth) return "";
  return fmt::format("authentication (key {}): {} authentic; refused {} unauthenticated, {} forged, {} replayed\n",
                     auth->key_file, auth->authenticated, auth->unauthenticated, auth->forged, auth->replayed);
}

void add_key_file_option(CLI::App& command, std::string& key_file) {
  command.add_option("--key-file,-k", key_file,
                     "shared key of an authenticating daemon ([auth] key_file): refuse messages without a valid "
                     "MAC, and replays (default: $COVTRACK_KEY_FILE; none: trailers are ignored)");
}

std::string receive_buffer_warning(const client::Subscriber& subscriber, const std::string& prefix) {
  const auto buffer = subscriber.receive_buffer();
  if (!buffer || buffer->note.empty()) return "";
  return fmt::format("{}warning: {}\n", prefix, buffer->note);
}

}  // namespace covtrack::cli
