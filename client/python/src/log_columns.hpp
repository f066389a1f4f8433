#pragma once
// An LCM log's pose and truth streams as columns, for read_log(): nothing in the file is
// trusted. Events come through LogReader (damaged byte ranges are skipped and reported),
// messages through decode_pose() / check_channel_message() and the client's validity
// checks (a bad message is counted by reason and left out), exactly as `covtrack view
// --log` reads a session.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/protocol/channels.hpp"
#include "covtrack/protocol/rejection_tally.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack::python {

// One row per message; the vectors of 3, 4 and 36 values per row are row-major.
struct TruthColumns {
  StreamId id;
  std::string parent_frame;  // of the stream's first message
  std::string child_frame;
  std::vector<std::int64_t> log_time_us;          // the log event's timestamp
  std::vector<std::int64_t> measurement_time_us;
  std::vector<std::int64_t> sequence;
  std::vector<double> position_m;                 // x y z
  std::vector<double> quaternion_wxyz;            // unit, w >= 0

  std::size_t size() const { return log_time_us.size(); }
  void add_pose(const Pose& T);
};

struct PoseColumns : TruthColumns {
  std::vector<std::int64_t> publish_time_us;
  std::vector<double> covariance;  // 6x6 BODY; +inf on the diagonal (0 elsewhere) when LOST
  std::vector<std::int8_t> status;  // TrackingStatus: 0 OK, 1 DEGRADED, 2 LOST
};

struct LogColumns {
  std::map<std::string, PoseColumns> poses;   // by "device/sensor"
  std::map<std::string, TruthColumns> truth;  // by "device/sensor"
  std::int64_t events = 0;                    // good events read, of every channel
  RejectionTally rejections;                  // pose and truth messages left out, by reason
  std::vector<lcmlog::LogDamage> damage;      // byte ranges that are no good event
};

// Fails only when the file cannot be opened or mapped; damage inside it is reported.
Result<LogColumns> read_log_columns(const std::string& path);

// A rotation's unit quaternion as w, x, y, z with w >= 0 (the wire's sign).
Eigen::Vector4d quaternion_wxyz(const Pose& T);

}  // namespace covtrack::python
