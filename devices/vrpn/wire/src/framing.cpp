#include "covtrack/vrpn/framing.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "covtrack/vrpn/byte_order.hpp"

namespace covtrack::vrpn {
namespace {
constexpr std::int64_t kMicro = 1'000'000;
}  // namespace

void append_message(std::vector<std::uint8_t>& out, const Message& m, std::uint32_t sequence) {
  // A time before 1970 cannot be written as VRPN's unsigned seconds: it is sent as 0.
  const std::int64_t t = std::max<std::int64_t>(m.time_us, 0);
  put_u32(out, static_cast<std::uint32_t>(kHeaderSize + m.payload.size()));
  put_u32(out, static_cast<std::uint32_t>(t / kMicro));
  put_u32(out, static_cast<std::uint32_t>(t % kMicro));
  put_i32(out, m.sender);
  put_i32(out, m.type);
  put_u32(out, sequence);
  out.insert(out.end(), m.payload.begin(), m.payload.end());
  out.resize(out.size() + padded(m.payload.size()) - m.payload.size(), 0);
}

Result<std::optional<Decoded>> decode_message(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kHeaderSize) return std::optional<Decoded>{};
  const std::uint32_t length = get_u32(bytes, 0);
  if (length < kHeaderSize)
    return fail(fmt::format("VRPN message length {} is below the {}-byte header", length, kHeaderSize));
  const std::size_t payload = length - kHeaderSize;
  if (padded(payload) > kMaxPaddedPayload)
    return fail(fmt::format("VRPN message of {} payload bytes is beyond VRPN's {}-byte limit", payload,
                            kMaxPaddedPayload));
  const std::size_t total = kHeaderSize + padded(payload);
  if (bytes.size() < total) return std::optional<Decoded>{};
  Decoded d;
  // A microsecond count of a second or more (not normalised by its sender) still adds up.
  d.message.time_us = std::int64_t{get_u32(bytes, 4)} * kMicro + get_u32(bytes, 8);
  d.message.sender = get_i32(bytes, 12);
  d.message.type = get_i32(bytes, 16);
  d.message.payload.assign(bytes.begin() + kHeaderSize, bytes.begin() + kHeaderSize + payload);
  d.consumed = total;
  return d;
}

Result<std::vector<Message>> decode_datagram(std::span<const std::uint8_t> datagram) {
  std::vector<Message> out;
  while (!datagram.empty()) {
    auto d = decode_message(datagram);
    if (!d) return std::unexpected(d.error());
    if (!*d) return fail(fmt::format("VRPN datagram ends inside a message ({} bytes left)", datagram.size()));
    out.push_back(std::move((*d)->message));
    datagram = datagram.subspan((*d)->consumed);
  }
  return out;
}

}  // namespace covtrack::vrpn
