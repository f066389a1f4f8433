#pragma once
// What every serial 6-DOF decoder promises about the records it returns, whatever the
// bytes: finite numbers, a unit quaternion (within quantisation), a position within the
// family's range; and that its counters add up.
#include <variant>
#include <vector>

#include "fuzz/fuzz_support.hpp"
#include "tracker_record.hpp"

namespace covtrack::fuzz {

inline void check_items(const std::vector<serial6dof::DecodedItem>& items) {
  for (const auto& item : items) {
    const auto* r = std::get_if<serial6dof::TrackerRecord>(&item);
    if (!r) continue;
    FUZZ_CHECK(r->position_m.allFinite() && r->orientation.coeffs().allFinite());
    FUZZ_CHECK(std::abs(r->orientation.norm() - 1.0) <= 0.02);
    FUZZ_CHECK(r->position_m.norm() <= 100.0);
    FUZZ_CHECK(!r->device_time_s || finite(*r->device_time_s));
  }
}

// Feeds the rest of `input` in chunks chosen by its next byte, checking every item.
template <typename Decoder>
void decode_and_check(Decoder& decoder, Input& input) {
  const std::uint8_t chunking = input.byte();
  const std::size_t size = input.rest().size();
  feed_in_chunks(input.rest(), chunking, 64,
                 [&](std::span<const std::uint8_t> chunk) { check_items(decoder.feed(chunk)); });
  FUZZ_CHECK(decoder.resyncs() <= size && decoder.bad_records() <= size);
}

}  // namespace covtrack::fuzz
