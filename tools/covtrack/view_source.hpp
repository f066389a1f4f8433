#pragma once
// Where `covtrack view` and `covtrack ar` take each frame's transform graph from: the
// scene's own values (its keyframe scripts run on scene time), the daemon's streams
// (--live), or a recorded session followed at its own time (--log).
#include <cstdint>
#include <expected>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "covtrack/client/subscriber.hpp"
#include "covtrack/client/transform_graph.hpp"
#include "covtrack/scene/scene_graph.hpp"
#include "frame_mismatches.hpp"
#include "regions_report.hpp"
#include "view_background.hpp"
#include "view_log.hpp"

namespace covtrack::cli {

struct ViewSourceArgs {
  bool live = false;
  std::string lcm_url;
  std::string key_file;  // --live: SubscriberOptions::key_file
  std::string log_path;
  double speed = 1;  // of the log's clock
};

// --live, --lcm-url, --key-file, --log and --speed on a view's subcommand.
void add_view_source_options(CLI::App& command, ViewSourceArgs& args);

struct ViewSourceError {
  std::string message;
  int exit_code;
};

// The newest report of a stream; empty when the view runs on the scene's values.
using LatestReport = std::function<std::optional<client::TrackedTransform>(const StreamId&)>;

class ViewSource {
 public:
  // `command` prefixes messages on stderr ("covtrack view").
  static std::expected<std::unique_ptr<ViewSource>, ViewSourceError> open(const RegionsModel& model,
                                                                          const ViewSourceArgs& args,
                                                                          std::string command);

  // With --live, says on stderr that the streams are followed. Scripts and tests wait for
  // this line, so it comes when the command is ready for them (its stop signals set).
  void announce() const;

  // Brings the graph to `elapsed_s` of the view: the log's events up to its time, or the
  // scene's keyframes at scene time. The time the frame is to be computed at.
  Result<std::int64_t> advance(double elapsed_s);

  bool live() const { return subscriber_ != nullptr; }
  bool finished() const { return log_ && log_->finished(); }  // the log has no events left
  LogFollower* log() { return log_ ? &*log_ : nullptr; }
  const client::TransformGraph& graph() const { return graph_; }
  const LatestReport& latest_report() const { return latest_report_; }
  const FrameMismatches& mismatches() const { return mismatches_; }

  // What this frame is drawn on: the log's latest camera frame when `log_frames` and it
  // has one, else the background's next (both at `size`, a copy to draw on).
  cv::Mat picture(ViewBackground& background, bool log_frames, cv::Size size, std::string& warning);

  // Stops the streams and tells on stderr what they brought and what was refused.
  void report_rejections();

 private:
  ViewSource(const RegionsModel& model, std::string command)
      : model_(model), command_(std::move(command)), mismatches_(command_) {}

  const RegionsModel& model_;
  std::string command_;
  client::TransformGraph graph_;
  std::unique_ptr<client::Subscriber> subscriber_;
  std::string lcm_url_;
  std::optional<LogFollower> log_;
  double speed_ = 1;
  std::optional<std::int64_t> fixed_at_;  // the scene's values are as fresh as this
  LatestReport latest_report_;
  FrameMismatches mismatches_;
};

}  // namespace covtrack::cli
