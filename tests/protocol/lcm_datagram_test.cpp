// LCM's UDP datagrams on bytes: decode_datagram() reads every field of well-formed short
// messages and fragments, and refuses each malformed shape with its fault; the Reassembler
// rebuilds fragmented messages and keeps to its bounds. Random and mutated datagrams
// are counted, never a crash. (Interop with a real LCM sender: udpm_receiver_test.)
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "covtrack/protocol/lcm_datagram.hpp"
#include "covtrack/protocol/lcm_reassembly.hpp"

using namespace covtrack::lcm_wire;
using Bytes = std::vector<std::byte>;

namespace {

void put32(Bytes& b, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(std::byte(v >> s));
}
void put16(Bytes& b, std::uint16_t v) {
  b.push_back(std::byte(v >> 8));
  b.push_back(std::byte(v));
}
void put_text(Bytes& b, const std::string& s, bool nul = true) {
  for (char c : s) b.push_back(std::byte(c));
  if (nul) b.push_back(std::byte{0});
}
Bytes payload_of(std::size_t n, unsigned seed = 1) {
  Bytes p(n);
  std::mt19937 rng(seed);
  for (auto& x : p) x = std::byte(rng());
  return p;
}

Bytes short_datagram(std::uint32_t seq, const std::string& channel, const Bytes& payload) {
  Bytes b;
  put32(b, kShortMagic);
  put32(b, seq);
  put_text(b, channel);
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

struct FragmentFields {
  std::uint32_t seq = 7, size = 0, offset = 0;
  std::uint16_t number = 0, count = 1;
  std::string channel;  // written when number == 0
};
Bytes fragment_datagram(const FragmentFields& f, const Bytes& data) {
  Bytes b;
  put32(b, kFragmentMagic);
  put32(b, f.seq);
  put32(b, f.size);
  put32(b, f.offset);
  put16(b, f.number);
  put16(b, f.count);
  if (f.number == 0) put_text(b, f.channel);
  b.insert(b.end(), data.begin(), data.end());
  return b;
}

// `payload` cut the way an LCM sender cuts it: fragment 0 carries the channel and
// `chunk` - channel - 1 bytes, the others `chunk` bytes each.
std::vector<Bytes> fragments_of(std::uint32_t seq, const std::string& channel, const Bytes& payload,
                                std::size_t chunk) {
  std::vector<Bytes> out;
  const std::size_t first = chunk - channel.size() - 1;
  const std::size_t count = 1 + (payload.size() - first + chunk - 1) / chunk;
  std::size_t offset = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t n = std::min(i == 0 ? first : chunk, payload.size() - offset);
    FragmentFields f{seq, static_cast<std::uint32_t>(payload.size()), static_cast<std::uint32_t>(offset),
                     static_cast<std::uint16_t>(i), static_cast<std::uint16_t>(count), channel};
    out.push_back(fragment_datagram(f, Bytes(payload.begin() + offset, payload.begin() + offset + n)));
    offset += n;
  }
  return out;
}

DatagramFault fault_of(const Bytes& b) {
  auto d = decode_datagram(b);
  EXPECT_FALSE(d) << "decoded a malformed datagram";
  return d ? DatagramFault::Duplicate : d.error().fault;
}

Fragment fragment(const Bytes& b) {
  auto d = decode_datagram(b);
  EXPECT_TRUE(d) << d.error().describe();
  return std::get<Fragment>(*d);
}

const Sender kA{0x7f000001, 40000}, kB{0x7f000001, 40001};

}  // namespace

TEST(LcmDatagram, ShortMessageFields) {
  const Bytes payload = payload_of(100);
  const Bytes bytes = short_datagram(0xdeadbeef, "covtrack/pose/a/b", payload);  // the views point into it
  auto d = decode_datagram(bytes);
  ASSERT_TRUE(d) << d.error().describe();
  const auto& m = std::get<ShortMessage>(*d);
  EXPECT_EQ(m.sequence, 0xdeadbeefu);
  EXPECT_EQ(m.channel, "covtrack/pose/a/b");
  EXPECT_EQ(Bytes(m.payload.begin(), m.payload.end()), payload);
}

TEST(LcmDatagram, EmptyPayloadAndLongestChannelPass) {
  const std::string longest(kMaxChannelBytes, 'c');
  const Bytes bytes = short_datagram(1, longest, {});
  auto d = decode_datagram(bytes);
  ASSERT_TRUE(d) << d.error().describe();
  EXPECT_EQ(std::get<ShortMessage>(*d).channel, longest);
  EXPECT_TRUE(std::get<ShortMessage>(*d).payload.empty());
}

TEST(LcmDatagram, MalformedShortMessagesAreRefusedWithTheirFault) {
  EXPECT_EQ(fault_of({}), DatagramFault::Truncated);
  EXPECT_EQ(fault_of(Bytes(7, std::byte{0x4c})), DatagramFault::Truncated);
  Bytes magic = short_datagram(1, "x", {});
  magic[3] = std::byte{'4'};
  EXPECT_EQ(fault_of(magic), DatagramFault::BadMagic);
  EXPECT_NE(decode_datagram(magic).error().detail.find("0x4c433034"), std::string::npos);
  Bytes unterminated;
  put32(unterminated, kShortMagic);
  put32(unterminated, 1);
  put_text(unterminated, "no-nul", false);
  EXPECT_EQ(fault_of(unterminated), DatagramFault::BadChannel);
  EXPECT_EQ(fault_of(short_datagram(1, std::string(kMaxChannelBytes + 1, 'c'), {})), DatagramFault::BadChannel);
}

TEST(LcmDatagram, FragmentFields) {
  const Bytes data = payload_of(50);
  const Bytes first_bytes = fragment_datagram({9, 1000, 0, 0, 3, "chan"}, data);
  auto first = fragment(first_bytes);
  EXPECT_EQ(first.sequence, 9u);
  EXPECT_EQ(first.message_size, 1000u);
  EXPECT_EQ(first.count, 3);
  EXPECT_EQ(first.channel, "chan");
  EXPECT_EQ(Bytes(first.data.begin(), first.data.end()), data);
  const Bytes later_bytes = fragment_datagram({9, 1000, 950, 2, 3, ""}, data);
  auto later = fragment(later_bytes);
  EXPECT_EQ(later.number, 2);
  EXPECT_EQ(later.offset, 950u);
  EXPECT_TRUE(later.channel.empty());  // only fragment 0 carries one
}

TEST(LcmDatagram, MalformedFragmentsAreRefusedWithTheirFault) {
  Bytes header_only = fragment_datagram({1, 10, 0, 1, 2, ""}, {});
  header_only.pop_back();
  EXPECT_EQ(fault_of(header_only), DatagramFault::Truncated);
  EXPECT_EQ(fault_of(fragment_datagram({1, 10, 0, 0, 0, "c"}, {})), DatagramFault::BadFragmentNumber);
  EXPECT_EQ(fault_of(fragment_datagram({1, 10, 0, 2, 2, ""}, {})), DatagramFault::BadFragmentNumber);
  EXPECT_EQ(fault_of(fragment_datagram({1, 10, 4, 0, 2, "c"}, payload_of(2))), DatagramFault::FragmentOutOfBounds);
  EXPECT_EQ(fault_of(fragment_datagram({1, 10, 8, 1, 2, ""}, payload_of(3))), DatagramFault::FragmentOutOfBounds);
  // An offset near 2^32 must not wrap around the bounds check.
  EXPECT_EQ(fault_of(fragment_datagram({1, 10, 0xffffffff, 1, 2, ""}, payload_of(3))),
            DatagramFault::FragmentOutOfBounds);
  Bytes unterminated = fragment_datagram({1, 10, 0, 1, 2, ""}, payload_of(4, 3));
  unterminated[17] = std::byte{0};  // fragment 0 now, whose channel has no NUL
  for (std::size_t i = 20; i < unterminated.size(); ++i) unterminated[i] = std::byte{'x'};
  EXPECT_EQ(fault_of(unterminated), DatagramFault::BadChannel);
}

TEST(LcmReassembly, RebuildsAMessageCutAsLcmCutsIt) {
  const Bytes payload = payload_of(200'000);
  Reassembler r;
  const auto parts = fragments_of(3, "big", payload, 65487);
  ASSERT_EQ(parts.size(), 4u);
  std::optional<CompleteMessage> done;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    auto out = r.add(kA, fragment(parts[i]), 1000, nullptr);
    ASSERT_TRUE(out) << out.error().describe();
    EXPECT_EQ(out->has_value(), i + 1 == parts.size());
    if (*out) done = std::move(**out);
  }
  ASSERT_TRUE(done);
  EXPECT_EQ(done->channel, "big");
  EXPECT_EQ(done->payload, payload);
  EXPECT_EQ(r.partial_messages(), 0u);
  EXPECT_EQ(r.bytes_held(), 0u);
  EXPECT_EQ(r.abandoned(), 0);
}

TEST(LcmReassembly, TwoSendersInterleaved) {
  const Bytes pa = payload_of(5000, 1), pb = payload_of(4000, 2);
  const auto a = fragments_of(1, "a", pa, 1000), b = fragments_of(1, "b", pb, 1000);
  Reassembler r;
  std::vector<CompleteMessage> done;
  for (std::size_t i = 0; i < std::max(a.size(), b.size()); ++i)
    for (auto [from, parts] : {std::pair{kA, &a}, std::pair{kB, &b}})
      if (i < parts->size())
        if (auto out = r.add(from, fragment((*parts)[i]), 0, nullptr); out && *out) done.push_back(std::move(**out));
  ASSERT_EQ(done.size(), 2u);
  EXPECT_EQ(done[0].channel, "b");  // b has fewer fragments
  EXPECT_EQ(done[0].payload, pb);
  EXPECT_EQ(done[1].payload, pa);
}

TEST(LcmReassembly, AnUnwantedChannelIsNotKeptAndItsFragmentsPassSilently) {
  Reassembler r;
  const auto parts = fragments_of(1, "other", payload_of(3000), 1000);
  int asked = 0;
  for (const auto& p : parts) {
    auto out = r.add(kA, fragment(p), 0, [&](std::string_view c) { ++asked; return c == "mine"; });
    ASSERT_TRUE(out);
    EXPECT_FALSE(*out);
  }
  EXPECT_EQ(asked, 1);
  EXPECT_EQ(r.bytes_held(), 0u);
  EXPECT_EQ(r.abandoned(), 0);
}

TEST(LcmReassembly, AFragmentWithoutItsFirstIsDropped) {
  Reassembler r;
  const auto parts = fragments_of(1, "c", payload_of(3000), 1000);
  for (std::size_t i = 1; i < parts.size(); ++i) {
    auto out = r.add(kA, fragment(parts[i]), 0, nullptr);
    ASSERT_TRUE(out);
    EXPECT_FALSE(*out);
  }
  EXPECT_EQ(r.partial_messages(), 0u);
}

TEST(LcmReassembly, ANewMessageFromTheSenderAbandonsTheUnfinishedOne) {
  Reassembler r;
  const auto first = fragments_of(1, "c", payload_of(3000, 1), 1000);
  const auto second = fragments_of(2, "c", payload_of(3000, 2), 1000);
  ASSERT_TRUE(r.add(kA, fragment(first[0]), 0, nullptr));
  std::optional<CompleteMessage> done;
  for (const auto& p : second)
    if (auto out = r.add(kA, fragment(p), 0, nullptr); out && *out) done = std::move(**out);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->payload, payload_of(3000, 2));
  EXPECT_EQ(r.abandoned(), 1);
  // A late fragment of the first message finds nothing to join.
  auto late = r.add(kA, fragment(first[1]), 0, nullptr);
  ASSERT_TRUE(late);
  EXPECT_FALSE(*late);
}

TEST(LcmReassembly, AStalePartialMessageIsEvicted) {
  ReassemblyLimits limits;
  limits.stale_after_us = 1000;
  Reassembler r(limits);
  const auto parts = fragments_of(1, "c", payload_of(3000), 1000);
  ASSERT_TRUE(r.add(kA, fragment(parts[0]), 0, nullptr));
  r.expire(500);
  EXPECT_EQ(r.partial_messages(), 1u);
  r.expire(1001);
  EXPECT_EQ(r.partial_messages(), 0u);
  EXPECT_EQ(r.bytes_held(), 0u);
  EXPECT_EQ(r.abandoned(), 1);
}

TEST(LcmReassembly, DuplicateAndInconsistentFragmentsAreRefused) {
  Reassembler r;
  const auto parts = fragments_of(1, "c", payload_of(3000), 1000);
  ASSERT_TRUE(r.add(kA, fragment(parts[0]), 0, nullptr));
  ASSERT_TRUE(r.add(kA, fragment(parts[1]), 0, nullptr));
  auto again = r.add(kA, fragment(parts[1]), 0, nullptr);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.error().fault, DatagramFault::Duplicate);
  auto other_size = r.add(kA, fragment(fragment_datagram({1, 3001, 2000, 2, 4, ""}, payload_of(10))), 0, nullptr);
  ASSERT_FALSE(other_size);
  EXPECT_EQ(other_size.error().fault, DatagramFault::Inconsistent);
  EXPECT_EQ(r.partial_messages(), 0u);
  EXPECT_EQ(r.abandoned(), 1);
}

TEST(LcmReassembly, FragmentsThatDoNotAddUpToTheSizeAreRefused) {
  Reassembler r;  // two fragments that overlap and leave a gap
  ASSERT_TRUE(r.add(kA, fragment(fragment_datagram({1, 100, 0, 0, 2, "c"}, payload_of(40))), 0, nullptr));
  auto out = r.add(kA, fragment(fragment_datagram({1, 100, 30, 1, 2, ""}, payload_of(40))), 0, nullptr);
  ASSERT_FALSE(out);
  EXPECT_EQ(out.error().fault, DatagramFault::Inconsistent);
  EXPECT_EQ(r.bytes_held(), 0u);
}

TEST(LcmReassembly, AMessageOverTheSizeBoundIsRefusedOnceAndNeverAllocated) {
  ReassemblyLimits limits;
  limits.max_message_bytes = 10'000;
  Reassembler r(limits);
  const auto parts = fragments_of(1, "c", payload_of(30'000), 1000);
  auto first = r.add(kA, fragment(parts[0]), 0, nullptr);
  ASSERT_FALSE(first);
  EXPECT_EQ(first.error().fault, DatagramFault::TooLarge);
  for (std::size_t i = 1; i < parts.size(); ++i) EXPECT_TRUE(r.add(kA, fragment(parts[i]), 0, nullptr));
  EXPECT_EQ(r.bytes_held(), 0u);
}

TEST(LcmReassembly, PartialMessagesStayWithinTheirBounds) {
  ReassemblyLimits limits;
  limits.max_partial_messages = 4;
  limits.max_message_bytes = 5000;
  limits.max_total_bytes = 12'000;
  Reassembler r(limits);
  for (std::uint16_t port = 0; port < 20; ++port) {
    const auto parts = fragments_of(1, "c", payload_of(4000), 1000);
    ASSERT_TRUE(r.add({1, port}, fragment(parts[0]), port, nullptr));
    EXPECT_LE(r.partial_messages(), 3u);  // 3 x 4000 bytes fill the 12,000
    EXPECT_LE(r.bytes_held(), limits.max_total_bytes);
  }
  EXPECT_EQ(r.abandoned(), 17);
  // The newest senders are the ones kept: the last one completes.
  const auto parts = fragments_of(1, "c", payload_of(4000), 1000);
  std::optional<CompleteMessage> done;
  for (std::size_t i = 1; i < parts.size(); ++i)
    if (auto out = r.add({1, 19}, fragment(parts[i]), 20, nullptr); out && *out) done = std::move(**out);
  EXPECT_TRUE(done);
}

// Mutated valid datagrams and random bytes: every one is decoded or refused, the
// reassembler never holds more than its bound, nothing crashes.
TEST(LcmReassembly, MutatedDatagramsAreRefusedOrDecodedNeverACrash) {
  ReassemblyLimits limits;
  limits.max_message_bytes = 1 << 20;
  limits.max_total_bytes = 4 << 20;
  Reassembler r(limits);
  std::vector<Bytes> seeds = fragments_of(5, "covtrack/pose/a/b", payload_of(5000), 1200);
  seeds.push_back(short_datagram(1, "covtrack/pose/a/b", payload_of(300)));
  std::mt19937 rng(42);
  int decoded = 0, refused = 0;
  for (int i = 0; i < 100'000; ++i) {
    Bytes b = seeds[rng() % seeds.size()];
    const int kind = static_cast<int>(rng() % 4);
    if (kind == 0) {
      b.resize(rng() % (b.size() + 1));
    } else if (kind == 1) {
      for (int k = 0; k < 4; ++k) b[rng() % b.size()] ^= std::byte(1u << (rng() % 8));
    } else if (kind == 2) {
      b[rng() % std::min<std::size_t>(b.size(), 24)] = std::byte(rng());
    } else {
      b.assign(rng() % 64, std::byte{});
      for (auto& x : b) x = std::byte(rng());
    }
    auto d = decode_datagram(b);
    if (!d) {
      ++refused;
      EXPECT_FALSE(d.error().detail.empty());
      continue;
    }
    ++decoded;
    if (const auto* f = std::get_if<Fragment>(&*d)) (void)r.add({1, static_cast<std::uint16_t>(rng() % 8)}, *f, i, nullptr);
    ASSERT_LE(r.bytes_held(), limits.max_total_bytes);
  }
  EXPECT_GT(decoded, 0);
  EXPECT_GT(refused, 0);
}
