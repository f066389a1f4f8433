#pragma once
// Bytes read from a Lenz interface, replayed through the protocol's decoder into the
// sections' occupancy, as the driver's receive path turns them (without its checks for
// impossible moves: the tests replay clean emulator sessions).
#include <functional>
#include <optional>
#include <span>
#include <variant>
#include <vector>

#include "feedback_state.hpp"
#include "track_layout.hpp"
#include "xpressnet_framing.hpp"
#include "xpressnet_messages.hpp"

namespace covtrack::test {

class OccupancyReplay {
 public:
  explicit OccupancyReplay(const lenz::TrackLayout& layout) : layout_(layout) {}

  // Calls on_change with every section's occupancy after each report that changed an input.
  void feed(std::span<const std::uint8_t> bytes,
            const std::function<void(const std::optional<std::vector<bool>>&)>& on_change) {
    for (const auto& frame : decoder_.push(bytes)) {
      const lenz::Reply reply = lenz::interpret_reply(frame);
      if (const auto* fb = std::get_if<lenz::Feedback>(&reply); fb && feedback_.apply(*fb))
        on_change(lenz::section_occupancy(layout_, feedback_));
    }
  }
  const lenz::FramingCounters& counters() const { return decoder_.counters(); }

 private:
  const lenz::TrackLayout& layout_;
  lenz::FrameDecoder decoder_;
  lenz::FeedbackState feedback_;
};

}  // namespace covtrack::test
