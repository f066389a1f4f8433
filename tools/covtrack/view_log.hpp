#pragma once
// `covtrack view --log FILE`: the view follows a recorded session's time. Pose events up
// to the current log time are fed to the transform graph, so regions (and staleness)
// are what a live view showed then. Damaged events are skipped (LogReader resyncs);
// pose messages that fail the wire checks (decode_pose()) or are invalid are counted by
// reason, never used. Camera frames (image_t) up to the same
// time give the picture behind the regions, as a live see-through view showed it.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "covtrack/client/tracked_transform.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "covtrack/lcmlog/log_reader.hpp"
#include "covtrack/protocol/rejection_tally.hpp"
#include "covtrack/protocol/result.hpp"
#include "frame_mismatches.hpp"

namespace covtrack::cli {

class LogFollower {
 public:
  static Result<LogFollower> open(const std::string& path);

  // Feeds every pose event with timestamp <= log_time_us into the graph (refusals of
  // reports in another parent frame are told through `mismatches`).
  void advance_to(std::int64_t log_time_us, client::TransformGraph& graph, FrameMismatches& mismatches);

  std::int64_t start_us() const { return start_us_; }
  bool finished() const { return !pending_; }
  std::optional<client::TrackedTransform> latest(const StreamId& id) const;
  const RejectionTally& rejections() const { return rejections_; }

  // The latest camera frame at or before the log time that decodes (BGR, its recorded
  // size), or an empty image before the first one. Only the first device seen sending
  // images is followed, so two cameras do not flicker. Decoded here, only when newer
  // frames came, newest first: a corrupt one is counted and described in `warning`, and
  // the one before it is tried (up to kKeptImages back), else the previous picture stays.
  const cv::Mat& image(std::string& warning);
  long corrupt_images() const { return corrupt_images_; }

 private:
  explicit LogFollower(lcmlog::LogReader reader) : reader_(std::move(reader)) {}
  void feed(const lcmlog::LogEvent& event, client::TransformGraph& graph, FrameMismatches& mismatches);
  void keep_image(const lcmlog::LogEvent& event);
  bool decode_frame(const std::vector<std::byte>& payload, std::int64_t time_us, std::string& warning);

  struct EncodedImage {
    std::vector<std::byte> payload;  // an image_t message
    std::int64_t time_us;               // its event's log time
  };
  // Frames overtaken before any was drawn: enough to step over a few corrupt ones while
  // a long --png wait does not hold the whole session in memory.
  static constexpr std::size_t kKeptImages = 4;

  lcmlog::LogReader reader_;
  std::optional<lcmlog::LogEvent> pending_;  // the next event, not yet due
  std::int64_t start_us_ = 0;
  std::map<std::string, client::TrackedTransform> latest_;  // by stream key
  RejectionTally rejections_;

  std::string image_device_;          // the camera followed; empty until one is seen
  std::deque<EncodedImage> undrawn_;  // its frames newer than image_, oldest first
  cv::Mat image_;                     // the last frame that decoded
  long corrupt_images_ = 0;
};

}  // namespace covtrack::cli
