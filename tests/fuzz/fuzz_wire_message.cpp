// Messages from the wire or a log: input = channel name, a zero byte, the message bytes.
// Each is checked against its channel (decode_pose, decode_status, ...); a pose that
// passes goes through the client's validity rules and into a TrackedTransform.
#include <algorithm>
#include <vector>

#include "covtrack/client/pose_validation.hpp"
#include "covtrack/protocol/channel_messages.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace covtrack;

namespace {

// A message that passes the checks is exactly the bytes LCM encodes for it: nothing was
// skipped or reinterpreted on the way in.
template <typename Msg>
void check_round_trip(const Msg& msg, std::span<const std::byte> bytes) {
  const int size = msg.getEncodedSize();
  FUZZ_CHECK(size == int(bytes.size()));
  std::vector<std::byte> again(bytes.size());
  FUZZ_CHECK(msg.encode(again.data(), 0, size) == size);
  FUZZ_CHECK(std::equal(again.begin(), again.end(), bytes.begin()));
}

void check_pose(const pose_cov_t& msg) {
  if (client::rejection_reason(msg)) return;
  const auto t = client::to_tracked_transform(msg, 0);
  FUZZ_CHECK(t.T_parent_child.matrix().allFinite());
  if (t.lost()) {
    FUZZ_CHECK(t.covariance.diagonal().array().isInf().all());
  } else {
    FUZZ_CHECK(t.covariance.allFinite());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto* text = reinterpret_cast<const char*>(data);
  const std::size_t split = std::find(text, text + size, '\0') - text;
  if (split == size) return 0;
  const std::string_view channel(text, split);
  const auto bytes = bytes_of(data + split + 1, size - split - 1);
  const auto rejection = check_channel_message(channel, bytes);
  if (rejection) FUZZ_CHECK(!rejection->describe().empty());
  if (channel.starts_with("covtrack/pose/")) {
    const auto msg = decode_pose(channel, bytes);
    FUZZ_CHECK(msg.has_value() == !rejection);
    if (msg) check_round_trip(*msg, bytes), check_pose(*msg);
  } else if (channel.starts_with("covtrack/status/")) {
    if (const auto msg = decode_status(channel, bytes)) check_round_trip(*msg, bytes);
  } else if (channel.starts_with("covtrack/claim/")) {
    if (const auto msg = decode_claim(channel, bytes)) check_round_trip(*msg, bytes);
  } else if (channel.starts_with("covtrack/image/")) {
    if (const auto msg = decode_image(channel, bytes)) check_round_trip(*msg, bytes);
  }
  return 0;
}
