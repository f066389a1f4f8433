#pragma once
// Messages checked against the channel they came on: decode_message()'s checks, and the
// device and sensor names the message holds must be its channel's.
#include <optional>
#include <span>
#include <string_view>

#include "covtrack/protocol/wire_decode.hpp"

namespace covtrack {

// covtrack/pose/<device>/<sensor>
Decoded<pose_cov_t> decode_pose(std::string_view channel, std::span<const std::byte> bytes);
// covtrack/status/<device>; also its values: a known state, a finite rate >= 0, a
// heartbeat period of 1 ms to 1 h (a client's unreachable timer depends on it).
Decoded<device_status_t> decode_status(std::string_view channel, std::span<const std::byte> bytes);
// covtrack/claim/<device>; also a known stage.
Decoded<device_claim_t> decode_claim(std::string_view channel, std::span<const std::byte> bytes);
// covtrack/image/<device>
Decoded<image_t> decode_image(std::string_view channel, std::span<const std::byte> bytes);

// The verdict on a message of any covtrack channel (pose, truth, status, claim, raw, image), for
// the tools that pass messages on as they are (record, replay). Nothing when it passes,
// or when the channel is not one of those kinds.
std::optional<WireRejection> check_channel_message(std::string_view channel, std::span<const std::byte> bytes);

}  // namespace covtrack
