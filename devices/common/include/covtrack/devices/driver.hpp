#pragma once
// The contract between a driver and the daemon that hosts it. A driver never touches
// LCM: it reads its device, turns bytes into poses with covariances, and hands them to
// a SampleSink. The daemon owns threads, restarts and publishing.
#include <cstddef>
#include <cstdint>
#include <stop_token>
#include <string>
#include <vector>

#include "covtrack/protocol/pose_message.hpp"
#include "covtrack/protocol/result.hpp"
#include "covtrack/protocol/se3.hpp"

namespace covtrack {

struct PoseSample {
  std::string sensor;
  std::string parent_frame;
  std::string child_frame;
  std::int64_t measurement_time_us = 0;
  Pose T_parent_child = Pose::Identity();
  Mat6 covariance = Mat6::Zero();  // BODY convention (protocol/README.md)
  TrackingStatus status = TrackingStatus::Ok;
};

struct TruthSample {
  std::string sensor;
  std::string parent_frame;
  std::string child_frame;
  std::int64_t measurement_time_us = 0;
  Pose T_parent_child = Pose::Identity();
};

// A camera frame as a whole compressed file (protocol/lcmtypes/image_t.lcm), with the
// measurement time of the poses measured in it.
struct ImageSample {
  std::int64_t measurement_time_us = 0;
  int width = 0;
  int height = 0;
  std::string encoding;  // "jpeg" or "png"
  std::vector<std::uint8_t> bytes;
};

enum class ByteDirection : std::int8_t { FromDevice = 0, ToDevice = 1 };

// Everything a driver reports. Calls come from the driver's own thread only.
class SampleSink {
 public:
  virtual ~SampleSink() = default;
  virtual void pose(const PoseSample& sample) = 0;
  virtual void truth(const TruthSample& sample) = 0;
  virtual void raw(ByteDirection direction, const std::uint8_t* data, std::size_t size) = 0;
  // Camera frames are optional: a sink that has no use for them drops them.
  virtual void image(const ImageSample&) {}
  // The device works but what it sees is worth a word, e.g. "no tag in view": a camera
  // that delivers frames without a tag sends no pose, and would otherwise look as if it
  // never started. The daemon shows the device RUNNING with this detail; an empty
  // detail clears it. Poses need no call: they mark the device RUNNING themselves.
  virtual void running(const std::string& /*detail*/) {}
  // Bad frames skipped by a decoder, resynchronisations, data the driver had to drop.
  virtual void count_error(const std::string& what) = 0;
  virtual void count_resync() = 0;
  virtual void count_drop() = 0;
};

class Driver {
 public:
  virtual ~Driver() = default;
  // Runs until stop is requested (returns success) or the device fails (returns the
  // error; the daemon restarts the driver after a back-off). Must notice a stop
  // request within 100 ms and must not throw. So no call may block for long: a path is
  // checked for its kind before it is opened (file_kind.hpp; a FIFO blocks an open), and
  // a device read waits with a timeout. A driver that does not return anyway is named at
  // the daemon's stop, after daemon.stop_timeout_s, and the daemon exits without it.
  virtual Result<void> run(SampleSink& sink, std::stop_token stop) = 0;
};

}  // namespace covtrack
