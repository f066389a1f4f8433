#include "publisher_identity.hpp"

#include <unistd.h>

#include <climits>
#include <random>

#include "covtrack/protocol/wire_text.hpp"

namespace covtrack::server {

PublisherIdentity PublisherIdentity::of_this_process() {
  PublisherIdentity id;
  std::random_device entropy;  // the kernel's: two daemons started together still differ
  const std::uint64_t high = entropy(), low = entropy();
  id.instance_id = static_cast<std::int64_t>((high << 32) | (low & 0xffffffffu));
  char host[HOST_NAME_MAX + 1] = {};
  if (::gethostname(host, sizeof host - 1) == 0) id.host = printable(host);  // clients want UTF-8
  id.pid = static_cast<std::int32_t>(::getpid());
  return id;
}

}  // namespace covtrack::server
