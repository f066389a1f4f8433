#include "line_noise.hpp"

namespace covtrack::emulate6dof {
namespace {

int events(double rate_per_s, double elapsed_s, std::mt19937_64& rng) {
  if (rate_per_s <= 0 || elapsed_s <= 0) return 0;
  return std::poisson_distribution<int>(rate_per_s * elapsed_s)(rng);
}

std::size_t any_byte(const std::vector<std::uint8_t>& bytes, std::mt19937_64& rng) {
  return std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng);
}

}  // namespace

int apply_line_noise(std::vector<std::uint8_t>& bytes, double elapsed_s, const LineNoiseRates& rates,
                     std::mt19937_64& rng) {
  int applied = 0;
  for (int n = events(rates.bit_flips_per_s, elapsed_s, rng); n > 0 && !bytes.empty(); --n, ++applied)
    bytes[any_byte(bytes, rng)] ^= static_cast<std::uint8_t>(1u << std::uniform_int_distribution<int>(0, 7)(rng));
  for (int n = events(rates.bytes_dropped_per_s, elapsed_s, rng); n > 0 && !bytes.empty(); --n, ++applied)
    bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(any_byte(bytes, rng)));
  for (int n = events(rates.bytes_duplicated_per_s, elapsed_s, rng); n > 0 && !bytes.empty(); --n, ++applied) {
    const auto at = bytes.begin() + static_cast<std::ptrdiff_t>(any_byte(bytes, rng));
    const std::uint8_t copy = *at;
    bytes.insert(at, copy);
  }
  return applied;
}

}  // namespace covtrack::emulate6dof
