#pragma once
// The inputs of the RS-bus feedback modules as last reported: each broadcast carries one
// nibble (inputs 1-4 or 5-8) of one module, so an input is known only once its nibble
// has been reported (docs/xpressnet.md, "Feedback" and "Sensor numbers").
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "track_layout.hpp"
#include "xpressnet_messages.hpp"

namespace covtrack::lenz {

class FeedbackState {
 public:
  // Applies the feedback-module pairs (turnout pairs are ignored); true if anything changed.
  bool apply(const Feedback& feedback);
  // Input 1-8 of RS-bus module 1-128: occupied or not, nothing while its nibble is unknown.
  std::optional<bool> input(int module, int input) const;
  // Inputs 1-4 (or 5-8) of the module at this wire address, as reported (bit 0 first).
  std::optional<std::uint8_t> nibble(std::uint8_t address, bool upper) const;
  void reset();

 private:
  std::array<std::uint8_t, 128> inputs_{};  // bit i = input i+1
  std::array<std::uint8_t, 128> known_{};   // bit 0: inputs 1-4 reported, bit 1: inputs 5-8
};

// Occupied or not for every section of the layout (in its order); nothing while some
// section's input has not been reported yet.
std::optional<std::vector<bool>> section_occupancy(const TrackLayout& layout, const FeedbackState& state);

}  // namespace covtrack::lenz
