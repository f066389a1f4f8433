#pragma once
// Who publishes, stamped on every heartbeat: clients tell a restarted daemon (a new
// instance id) from a second one publishing the same device (two ids that both go on).
#include <cstdint>
#include <string>

namespace covtrack::server {

struct PublisherIdentity {
  std::int64_t instance_id = 0;  // random, drawn once per start
  std::string host;
  std::int32_t pid = 0;

  static PublisherIdentity of_this_process();
};

}  // namespace covtrack::server
