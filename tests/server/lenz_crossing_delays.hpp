#pragma once
// How late each section crossing reached the daemon: when the locomotive really entered a
// section (from the emulator's truth poses) against when the daemon read the occupancy
// report of it (from its raw bytes, stamped as read). The dead-reckoning model assumes a
// crossing is read at most `crossing_latency_s` late after the command station sent it,
// and the driver allows for its own hold-ups. A stalled emulator (the command station)
// breaks that premise: the poses after such a crossing test the machine, not the
// covariance. The emulator's own truth stream shows its stalls, as gaps.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "covtrack/protocol/se3.hpp"
#include "support/along_track.hpp"
#include "support/occupancy_replay.hpp"
#include "track_layout.hpp"

namespace covtrack::test {

struct Crossing {
  std::size_t section = 0;  // the section entered
  double true_s = 0;        // when the locomotive's front entered it
  double read_s = INFINITY;  // when the daemon read the report of it (never: infinity)
  bool emulator_stalled = false;  // the emulator was held up as the locomotive crossed
  bool daemon_stalled = false;    // the daemon was held up before it read it (mark_daemon_stalls)
  double delay_s() const { return read_s - true_s; }
};

struct RawRead {
  std::int64_t time_us;
  std::vector<std::uint8_t> bytes;
};

// The emulator publishes its truth every 20 ms, the daemon's simulated device every 10 ms;
// a gap this long in either means that process was held up.
inline constexpr double kStall_s = 0.04;

// Every section the locomotive entered while the truth ran (travel forwards only, as in
// the test's profile), its entry time interpolated between the truth samples around it.
inline std::vector<Crossing> true_crossings(const lenz::TrackLayout& layout,
                                            const std::map<std::int64_t, Pose>& truth) {
  std::vector<Crossing> out;
  bool first = true;
  double prev_t = 0, prev_s = 0;
  for (const auto& [time_us, pose] : truth) {
    const double t = static_cast<double>(time_us) * 1e-6, s = along_track_of(layout, pose.translation());
    if (!first && layout.section_at(s) != layout.section_at(prev_s)) {
      const std::size_t entered = layout.section_at(s);
      const double moved = layout.wrap(s - prev_s);
      const double to_boundary = layout.wrap(layout.sections()[entered].start_s - prev_s);
      Crossing c{entered, prev_t + (t - prev_t) * std::clamp(to_boundary / moved, 0.0, 1.0)};
      c.emulator_stalled = t - prev_t >= kStall_s;
      out.push_back(c);
    }
    first = false;
    prev_t = t, prev_s = s;
  }
  return out;
}

// When the daemon read each change of the occupied section, by replaying its raw bytes
// (from the device, in order) through the protocol's decoder.
inline std::vector<std::pair<double, std::size_t>> occupancy_reads(const lenz::TrackLayout& layout,
                                                                   const std::vector<RawRead>& raw) {
  std::vector<std::pair<double, std::size_t>> out;
  OccupancyReplay replay(layout);
  for (const auto& read : raw)
    replay.feed(read.bytes, [&](const std::optional<std::vector<bool>>& occupied) {
      if (!occupied || std::count(occupied->begin(), occupied->end(), true) != 1) return;
      const auto section = static_cast<std::size_t>(std::find(occupied->begin(), occupied->end(), true) - occupied->begin());
      if (out.empty() || out.back().second != section) out.push_back({static_cast<double>(read.time_us) * 1e-6, section});
    });
  return out;
}

// The true crossings with the time each was read: the first read of the section entered
// after it was entered (less 5 ms for the truth's interpolation).
inline std::vector<Crossing> crossing_delays(const lenz::TrackLayout& layout, const std::map<std::int64_t, Pose>& truth,
                                             const std::vector<RawRead>& raw) {
  auto crossings = true_crossings(layout, truth);
  const auto reads = occupancy_reads(layout, raw);
  for (auto& c : crossings)
    for (const auto& [read_s, section] : reads)
      if (section == c.section && read_s >= c.true_s - 5e-3) {
        c.read_s = read_s;
        break;
      }
  return crossings;
}

// Marks the crossings the daemon was held up for: between the crossing and its read (for
// one never read, any time after it), `stamps_us` (a stream the daemon publishes
// steadily, in order) has a gap of kStall_s.
inline void mark_daemon_stalls(std::vector<Crossing>& crossings, const std::vector<std::int64_t>& stamps_us) {
  for (auto& c : crossings)
    for (std::size_t i = 1; i < stamps_us.size(); ++i) {
      const double before = static_cast<double>(stamps_us[i - 1]) * 1e-6, after = static_cast<double>(stamps_us[i]) * 1e-6;
      if (before < c.read_s && after > c.true_s && after - before >= kStall_s) {
        c.daemon_stalled = true;
        break;
      }
    }
}

// Whether the estimate at time t rests on a crossing that the emulator, held up, sent
// later than `latency_s`: one of the last two read by t (the section the locomotive is
// in, and the traversal that gave its speed), or one it had made by t not yet read.
inline bool rests_on_a_late_command_station(const std::vector<Crossing>& crossings, double t, double latency_s) {
  int read = 0;
  for (auto it = crossings.rbegin(); it != crossings.rend() && read < 2; ++it) {
    if (it->true_s >= t) continue;
    read += it->read_s <= t;
    if (it->emulator_stalled && it->delay_s() > latency_s) return true;
  }
  return false;
}

}  // namespace covtrack::test
