#include <algorithm>
#include <array>

#include "covtrack/client/label_placer.hpp"

namespace covtrack::client {
namespace {

enum class Side { right, top, bottom, left };

// Beside one side, centred on the object, then slid along the side by whole label
// lengths in both directions, so neighbours' labels can stack.
constexpr int kSlidesEachWay = 3;

void append_side(Side side, const Box& o, const Vec2& s, double gap, std::vector<Box>& out) {
  const Vec2 c = o.center();
  for (int k = 0; k <= 2 * kSlidesEachWay; ++k) {
    const int slide = (k + 1) / 2 * (k % 2 ? 1 : -1);  // 0, 1, -1, 2, -2, ...
    Vec2 center;
    switch (side) {
      case Side::right: center = {o.max.x() + gap + s.x() / 2, c.y() + slide * (s.y() + gap)}; break;
      case Side::left: center = {o.min.x() - gap - s.x() / 2, c.y() + slide * (s.y() + gap)}; break;
      // v grows downwards: "top" is the smaller v.
      case Side::top: center = {c.x() + slide * (s.x() + gap), o.min.y() - gap - s.y() / 2}; break;
      case Side::bottom: center = {c.x() + slide * (s.x() + gap), o.max.y() + gap + s.y() / 2}; break;
    }
    out.push_back(box_at_center(center, s));
  }
}

std::vector<Box> candidates(std::span<const Side> sides, const Box& o, const Vec2& s, double gap) {
  std::vector<Box> out;
  out.reserve(sides.size() * (2 * kSlidesEachWay + 1));  // one allocation per label, not six
  for (Side side : sides) append_side(side, o, s, gap, out);
  return out;
}

}  // namespace

LabelPolicy fixed_order_policy() {
  return [](const Box& o, const Vec2& s, const Box&, double gap) {
    constexpr std::array sides = {Side::right, Side::top, Side::bottom, Side::left};
    return candidates(sides, o, s, gap);
  };
}

LabelPolicy most_free_space_policy() {
  return [](const Box& o, const Vec2& s, const Box& screen, double gap) {
    std::array<std::pair<double, Side>, 4> free = {{
        {screen.max.x() - o.max.x(), Side::right},
        {o.min.y() - screen.min.y(), Side::top},
        {screen.max.y() - o.max.y(), Side::bottom},
        {o.min.x() - screen.min.x(), Side::left},
    }};
    std::stable_sort(free.begin(), free.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    std::array<Side, 4> sides;
    for (std::size_t i = 0; i < 4; ++i) sides[i] = free[i].second;
    return candidates(sides, o, s, gap);
  };
}

}  // namespace covtrack::client
