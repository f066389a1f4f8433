#pragma once
// Pure decoder of Ascension Flock of Birds POSITION/QUATERNION records
// (laserBIRD guide): 7 phased 14-bit words (x, y, z, q0..q3; q0 scalar), plus the bird's
// FBB address in group mode. Resyncs on the phasing bit (bit 7 set only in a record's
// first byte).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "resync_buffer.hpp"
#include "tracker_record.hpp"

namespace covtrack::serial6dof {

struct FlockFormat {
  double position_scale_in = 36;  // full scale: 36 (standard), 72, or 144 (extended range)
  bool group_mode = false;        // a 15th byte carries the bird's address
  int standalone_station = 1;     // the station reported when not in group mode
};

std::size_t flock_record_size(const FlockFormat& format);

class FlockDecoder {
 public:
  explicit FlockDecoder(FlockFormat format) : format_(format) {}

  std::vector<DecodedItem> feed(std::span<const std::uint8_t> bytes);

  std::uint64_t resyncs() const { return input_.resyncs(); }
  std::uint64_t bad_records() const { return input_.bad_records(); }
  const std::string& last_problem() const { return input_.last_problem(); }

 private:
  void skip_to_next_record();

  FlockFormat format_;
  ResyncBuffer input_;
};

}  // namespace covtrack::serial6dof
