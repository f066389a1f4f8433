// VRPN's wire protocol as covtrackd's VRPN server meets it: anyone who reaches its port
// can send it anything. The input is what a peer sends on TCP: the server's session
// takes it whole and, in another session, in the chunks a read would deliver; the two
// must agree (the same messages, the same bytes to send back), and fail together. Each
// tracker report is decoded as the vrpn driver decodes it. The input is also taken as one
// UDP datagram, and as the payload of each system message.
#include <vector>

#include "covtrack/vrpn/message_names.hpp"
#include "covtrack/vrpn/session.hpp"
#include "covtrack/vrpn/system_messages.hpp"
#include "covtrack/vrpn/tracker_report.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace covtrack;
using namespace covtrack::vrpn;

namespace {

constexpr std::int64_t kNowUs = 1'700'000'000'000'000;

// The names covtrackd's VRPN server describes: its trackers and the types it sends.
Session server_session() {
  return Session({"Tracker0", "Tracker1"}, {std::string(kTrackerPosQuat), std::string(kPong)});
}

void check_messages(const std::vector<NamedMessage>& messages) {
  for (const NamedMessage& m : messages) {
    FUZZ_CHECK(!m.sender.empty() && !m.type.empty());
    if (m.type != kTrackerPosQuat) continue;
    const auto report = decode_pos_quat(m.payload);
    if (!report) {
      FUZZ_CHECK(!report.error().message.empty());
      continue;
    }
    const Pose T = pose_of(*report);
    FUZZ_CHECK(T.matrix().allFinite());
    FUZZ_CHECK((T.rotation().transpose() * T.rotation()).isIdentity(1e-9));
  }
}

bool same(const NamedMessage& a, const NamedMessage& b) {
  return a.sender == b.sender && a.type == b.type && a.time_us == b.time_us && a.payload == b.payload;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in({data, size});
  const std::uint8_t chunk_seed = in.byte();
  const std::span<const std::uint8_t> stream = in.rest();

  Session whole = server_session();
  const auto all_at_once = whole.receive(stream, kNowUs);
  if (all_at_once) {
    check_messages(*all_at_once);
  } else {
    FUZZ_CHECK(!all_at_once.error().message.empty());
  }

  Session chunked = server_session();
  std::vector<NamedMessage> in_chunks;
  bool failed = false;
  fuzz::feed_in_chunks(stream, chunk_seed, 64, [&](std::span<const std::uint8_t> chunk) {
    if (failed) return;
    auto got = chunked.receive(chunk, kNowUs);
    if (!got) {
      failed = true;
      return;
    }
    for (NamedMessage& m : *got) in_chunks.push_back(std::move(m));
  });
  FUZZ_CHECK(failed == !all_at_once);
  if (all_at_once) {
    FUZZ_CHECK(in_chunks.size() == all_at_once->size());
    for (std::size_t i = 0; i < in_chunks.size(); ++i) FUZZ_CHECK(same(in_chunks[i], (*all_at_once)[i]));
    FUZZ_CHECK(chunked.ready() == whole.ready());
    FUZZ_CHECK(chunked.undescribed() == whole.undescribed());
    FUZZ_CHECK(chunked.take_output() == whole.take_output());
    if (const auto& udp = whole.peer_udp()) FUZZ_CHECK(udp->port >= 1 && udp->port <= 65535);
  }

  // The same bytes as one datagram, to a session past its handshake.
  Session after_handshake = server_session();
  const Cookie cookie = make_cookie();
  FUZZ_CHECK(after_handshake.receive(cookie, kNowUs).has_value() && after_handshake.ready());
  if (const auto datagram = after_handshake.receive_datagram(stream)) check_messages(*datagram);

  if (const auto name = parse_name_description(stream)) FUZZ_CHECK(name->size() <= kMaxVrpnNameLength);
  (void)parse_udp_description(stream);
  return 0;
}
