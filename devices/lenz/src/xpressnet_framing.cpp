#include "xpressnet_framing.hpp"

namespace covtrack::lenz {
namespace {

std::uint8_t xor_of(std::span<const std::uint8_t> bytes) {
  std::uint8_t x = 0;
  for (auto b : bytes) x ^= b;
  return x;
}

// Bytes with high nibble F precede messages on the LI-USB; F0 and F2 are the only LI
// headers in that range (version request, address/baud request and replies).
bool is_prefix_byte(std::uint8_t b) { return (b & 0xF0) == 0xF0 && b != 0xF0 && b != 0xF2; }

}  // namespace

Prefix FrameDecoder::prefix_before(std::size_t header) const {
  if (header < 2 || pending_[header - 2] != 0xFF) return Prefix::None;
  if (pending_[header - 1] == 0xFE) return Prefix::Reply;
  if (pending_[header - 1] == 0xFD) return Prefix::Unsolicited;
  return Prefix::None;
}

std::vector<std::uint8_t> encode_frame(std::span<const std::uint8_t> header_and_data) {
  std::vector<std::uint8_t> out(header_and_data.begin(), header_and_data.end());
  out.push_back(xor_of(header_and_data));
  return out;
}

std::vector<std::uint8_t> encode_frame(std::span<const std::uint8_t> header_and_data, Prefix prefix) {
  std::vector<std::uint8_t> out;
  if (prefix == Prefix::Reply) out = {0xFF, 0xFE};
  if (prefix == Prefix::Unsolicited) out = {0xFF, 0xFD};
  const auto frame = encode_frame(header_and_data);
  out.insert(out.end(), frame.begin(), frame.end());
  return out;
}

void FrameDecoder::reset() {
  pending_.clear();
  prefix_ = Prefix::None;
  in_sync_ = true;
}

std::optional<std::size_t> FrameDecoder::complete_frame_after(std::size_t pos) const {
  for (std::size_t q = pos + 1; q < pending_.size(); ++q) {
    if (is_prefix_byte(pending_[q])) continue;
    const std::size_t length = static_cast<std::size_t>(pending_[q] & 0x0F) + 2;
    if (length < 3 || q + length > pending_.size()) continue;
    // In step, only a frame that ends where the input ends: a header whose body is still
    // arriving has no more bytes after it, so one that does is not a header.
    if (in_sync_ && q + length != pending_.size()) continue;
    if (xor_of({pending_.data() + q, length}) == 0) return q;
  }
  return std::nullopt;
}

std::vector<Frame> FrameDecoder::push(std::span<const std::uint8_t> bytes) {
  pending_.insert(pending_.end(), bytes.begin(), bytes.end());
  std::vector<Frame> frames;
  std::size_t pos = 0;
  while (pos < pending_.size()) {
    const std::uint8_t head = pending_[pos];
    if (is_prefix_byte(head)) {
      // FF FE / FF FD: the byte just before the header tells reply from broadcast.
      if (head == 0xFE) prefix_ = Prefix::Reply;
      else if (head == 0xFD) prefix_ = Prefix::Unsolicited;
      else if (head != 0xFF) ++counters_.skipped_bytes;
      ++pos;
      continue;
    }
    const std::size_t length = static_cast<std::size_t>(head & 0x0F) + 2;
    if (pending_.size() - pos < length) {
      // Wait for the rest, unless a whole frame follows: then this byte was not a header
      // (a stray byte whose low nibble asks for up to 17 more), and that frame must not
      // wait behind it for bytes of later frames.
      const auto next = complete_frame_after(pos);
      if (!next) break;
      if (in_sync_) ++counters_.bad_frames;
      in_sync_ = false;
      counters_.skipped_bytes += *next - pos;
      prefix_ = prefix_before(*next);
      pos = *next;
      continue;
    }
    const std::span<const std::uint8_t> candidate(pending_.data() + pos, length);
    if (xor_of(candidate) != 0) {
      // Not a frame (garbage, or a corrupted one): skip this byte only, so a real header
      // inside the bytes taken for this one's body is still found. One run of such bytes
      // is one bad frame.
      if (in_sync_) ++counters_.bad_frames;
      in_sync_ = false;
      ++counters_.skipped_bytes;
      prefix_ = Prefix::None;
      ++pos;
      continue;
    }
    frames.push_back(Frame{{candidate.begin(), candidate.end() - 1}, prefix_});
    in_sync_ = true;
    ++counters_.frames;
    prefix_ = Prefix::None;
    pos += length;
  }
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(pos));
  return frames;
}

}  // namespace covtrack::lenz
