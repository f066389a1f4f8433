#include "covtrack/protocol/lcm_datagram.hpp"

#include <cstring>

#include <fmt/format.h>

#include "rejection.hpp"

namespace covtrack::lcm_wire {
namespace {

std::uint32_t be32(const std::byte* p) {
  return (std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) | (std::uint32_t(p[2]) << 8) |
         std::uint32_t(p[3]);
}
std::uint16_t be16(const std::byte* p) { return static_cast<std::uint16_t>((std::uint32_t(p[0]) << 8) | std::uint32_t(p[1])); }

// The NUL-terminated channel at the start of `rest`; what follows it is the data.
std::expected<std::string_view, DatagramRejection> channel_at(std::span<const std::byte> rest) {
  const auto* begin = reinterpret_cast<const char*>(rest.data());
  const auto* nul = static_cast<const char*>(std::memchr(begin, '\0', rest.size()));
  if (!nul)
    return reject(DatagramFault::BadChannel,
                  fmt::format("no NUL ends the channel in the {} bytes after the header", rest.size()));
  const std::string_view channel(begin, static_cast<std::size_t>(nul - begin));
  if (channel.size() > kMaxChannelBytes)
    return reject(DatagramFault::BadChannel,
                  fmt::format("a channel of {} bytes (at most {})", channel.size(), kMaxChannelBytes));
  return channel;
}

std::expected<Datagram, DatagramRejection> decode_fragment(std::span<const std::byte> bytes) {
  if (bytes.size() < kFragmentHeaderBytes)
    return reject(DatagramFault::Truncated, fmt::format("a fragment of {} bytes is shorter than its {}-byte header",
                                                        bytes.size(), kFragmentHeaderBytes));
  Fragment f{be32(&bytes[4]), be32(&bytes[8]), be32(&bytes[12]), be16(&bytes[16]), be16(&bytes[18]), {}, {}};
  if (f.number >= f.count)
    return reject(DatagramFault::BadFragmentNumber, fmt::format("fragment {} of {}", f.number, f.count));
  auto rest = bytes.subspan(kFragmentHeaderBytes);
  if (f.number == 0) {
    auto channel = channel_at(rest);
    if (!channel) return std::unexpected(channel.error());
    if (f.offset != 0)
      return reject(DatagramFault::FragmentOutOfBounds, fmt::format("fragment 0 at offset {}", f.offset));
    f.channel = *channel;
    rest = rest.subspan(channel->size() + 1);
  }
  f.data = rest;
  if (std::uint64_t{f.offset} + f.data.size() > f.message_size)
    return reject(DatagramFault::FragmentOutOfBounds,
                  fmt::format("fragment {} of {}: {} bytes at offset {} pass the message size {}", f.number, f.count,
                              f.data.size(), f.offset, f.message_size));
  return f;
}

}  // namespace

const char* to_string(DatagramFault fault) {
  switch (fault) {
    case DatagramFault::Truncated: return "truncated datagram";
    case DatagramFault::BadMagic: return "bad magic";
    case DatagramFault::BadChannel: return "bad datagram channel";
    case DatagramFault::BadFragmentNumber: return "bad fragment number";
    case DatagramFault::FragmentOutOfBounds: return "fragment out of bounds";
    case DatagramFault::TooLarge: return "message too large";
    case DatagramFault::Inconsistent: return "inconsistent fragment";
    case DatagramFault::Duplicate: return "duplicate fragment";
  }
  return "unknown datagram fault";
}

std::expected<Datagram, DatagramRejection> decode_datagram(std::span<const std::byte> bytes) {
  if (bytes.size() < kShortHeaderBytes)
    return reject(DatagramFault::Truncated,
                  fmt::format("{} bytes, shorter than LCM's {}-byte header", bytes.size(), kShortHeaderBytes));
  const std::uint32_t magic = be32(bytes.data());
  if (magic == kFragmentMagic) return decode_fragment(bytes);
  if (magic != kShortMagic)
    return reject(DatagramFault::BadMagic, fmt::format("0x{:08x} (LCM sends 0x{:08x} or 0x{:08x})", magic,
                                                       kShortMagic, kFragmentMagic));
  const auto rest = bytes.subspan(kShortHeaderBytes);
  auto channel = channel_at(rest);
  if (!channel) return std::unexpected(channel.error());
  return ShortMessage{be32(&bytes[4]), *channel, rest.subspan(channel->size() + 1)};
}

}  // namespace covtrack::lcm_wire
