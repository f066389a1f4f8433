#pragma once
// What a bad serial line does to bytes in flight: bits flip, bytes vanish, bytes arrive
// twice. Events come as a Poisson process in time; each hits a random byte of what is
// sent at that moment.
#include <cstdint>
#include <random>
#include <vector>

namespace covtrack::emulate6dof {

struct LineNoiseRates {
  double bit_flips_per_s = 0;
  double bytes_dropped_per_s = 0;
  double bytes_duplicated_per_s = 0;
  bool any() const { return bit_flips_per_s > 0 || bytes_dropped_per_s > 0 || bytes_duplicated_per_s > 0; }
};

// Mutates `bytes` (sent `elapsed_s` after the previous call) in place; returns how many
// events were applied.
int apply_line_noise(std::vector<std::uint8_t>& bytes, double elapsed_s, const LineNoiseRates& rates,
                     std::mt19937_64& rng);

}  // namespace covtrack::emulate6dof
