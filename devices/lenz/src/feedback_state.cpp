#include "feedback_state.hpp"

namespace covtrack::lenz {

bool FeedbackState::apply(const Feedback& feedback) {
  bool changed = false;
  for (const auto& pair : feedback.pairs) {
    if (!pair.is_feedback_module() || pair.address >= inputs_.size()) continue;
    const int shift = pair.upper_nibble() ? 4 : 0;
    const std::uint8_t mask = static_cast<std::uint8_t>(0x0F << shift);
    const std::uint8_t before = inputs_[pair.address];
    const std::uint8_t after = static_cast<std::uint8_t>((before & ~mask) | (pair.inputs() << shift));
    const std::uint8_t known_bit = pair.upper_nibble() ? 2 : 1;
    changed = changed || before != after || !(known_[pair.address] & known_bit);
    inputs_[pair.address] = after;
    known_[pair.address] |= known_bit;
  }
  return changed;
}

std::optional<bool> FeedbackState::input(int module, int input) const {
  if (module < 1 || module > 128 || input < 1 || input > 8) return std::nullopt;
  const int address = module - 1;  // the wire carries the RS-bus address minus one
  const std::uint8_t known_bit = input > 4 ? 2 : 1;
  if (!(known_[address] & known_bit)) return std::nullopt;
  return ((inputs_[address] >> (input - 1)) & 1) != 0;
}

std::optional<std::uint8_t> FeedbackState::nibble(std::uint8_t address, bool upper) const {
  if (address >= inputs_.size() || !(known_[address] & (upper ? 2 : 1))) return std::nullopt;
  return static_cast<std::uint8_t>((upper ? inputs_[address] >> 4 : inputs_[address]) & 0x0F);
}

void FeedbackState::reset() {
  inputs_.fill(0);
  known_.fill(0);
}

std::optional<std::vector<bool>> section_occupancy(const TrackLayout& layout, const FeedbackState& state) {
  std::vector<bool> occupied;
  for (const auto& s : layout.sections()) {
    const auto in = state.input(s.input.module, s.input.input);
    if (!in) return std::nullopt;
    occupied.push_back(*in);
  }
  return occupied;
}

}  // namespace covtrack::lenz
