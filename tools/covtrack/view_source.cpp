#include "view_source.hpp"

#include <cmath>
#include <iostream>

#include <fmt/format.h>

#include "covtrack/program/command_line.hpp"
#include "covtrack/protocol/clock.hpp"
#include "covtrack/protocol/lcm_url.hpp"
#include "subscriber_summary.hpp"

namespace covtrack::cli {

void add_view_source_options(CLI::App& command, ViewSourceArgs& args) {
  command.add_flag("--live", args.live, "Tracked transforms from the daemon's streams, not the scene's values");
  command.add_option("--lcm-url,-u", args.lcm_url, "LCM URL for --live (default: $LCM_DEFAULT_URL or LCM's)");
  add_key_file_option(command, args.key_file);
  command.add_option("--log", args.log_path, "Follow a recorded session (LCM log) at its own time");
  command.add_option("--speed,-s", args.speed, "Speed factor of --log")
      ->capture_default_str()
      ->check(program::in_range(0.01, 1000.0));
}

std::expected<std::unique_ptr<ViewSource>, ViewSourceError> ViewSource::open(const RegionsModel& model,
                                                                             const ViewSourceArgs& args,
                                                                             std::string command) {
  const auto error = [](std::string message, int code) { return std::unexpected(ViewSourceError{std::move(message), code}); };
  if (args.live && !args.log_path.empty()) return error("--live and --log exclude each other", 2);
  std::unique_ptr<ViewSource> s(new ViewSource(model, std::move(command)));
  s->speed_ = args.speed;
  if (!args.live && args.log_path.empty()) s->fixed_at_ = covtrack::now_us();
  if (auto r = scene::add_scene_transforms(model.scene, s->graph_, s->fixed_at_); !r)
    return error(fmt::format("{}: {}", model.scene_path, r.error().message), 2);
  if (args.live) {
    auto sub = client::Subscriber::open({.lcm_url = args.lcm_url, .key_file = args.key_file});
    if (!sub) return error(sub.error().message, program::kExitRuntimeError);
    s->subscriber_ = std::move(*sub);
    std::cerr << receive_buffer_warning(*s->subscriber_, s->command_ + ": ");
    // Streams the scene does not use are simply not in the graph.
    ViewSource* self = s.get();
    (void)self->subscriber_->on_pose(".*", [self](const client::TrackedTransform& t) {
      self->mismatches_.update(self->graph_, t);
    });
    s->latest_report_ = [self](const StreamId& id) { return self->subscriber_->latest(id); };
    s->lcm_url_ = effective_lcm_url(args.lcm_url);
  }
  if (!args.log_path.empty()) {
    auto opened = LogFollower::open(args.log_path);
    if (!opened) return error(opened.error().message, 2);
    s->log_.emplace(std::move(*opened));
    ViewSource* self = s.get();
    s->latest_report_ = [self](const StreamId& id) { return self->log_->latest(id); };
  }
  return s;
}

void ViewSource::announce() const {
  if (live()) std::cerr << command_ << ": following the streams on " << lcm_url_ << "\n";
}

Result<std::int64_t> ViewSource::advance(double elapsed_s) {
  if (log_) {
    // The log's clock runs at --speed from its first event.
    const std::int64_t log_time = log_->start_us() + std::llround(elapsed_s * speed_ * 1e6);
    log_->advance_to(log_time, graph_, mismatches_);
    return log_time;
  }
  // Fixed scene values are as fresh as when they were set: no staleness grows on them.
  if (!fixed_at_) return covtrack::now_us();
  if (auto r = scene::report_keyframes(model_.scene, graph_, elapsed_s, *fixed_at_); !r)
    return fail(fmt::format("{}: {}", model_.scene_path, r.error().message));
  return *fixed_at_;
}

cv::Mat ViewSource::picture(ViewBackground& background, bool log_frames, cv::Size size, std::string& warning) {
  if (log_ && log_frames)
    if (const cv::Mat& frame = log_->image(warning); !frame.empty()) return fit_to_view(frame, size);
  return background.next(warning);
}

void ViewSource::report_rejections() {
  if (subscriber_) {
    subscriber_->stop();
    std::cerr << subscriber_summary(*subscriber_, command_ + ": ");
  }
  if (log_ && log_->rejections().total > 0)
    std::cerr << command_ << ": rejected pose messages of the log: " << log_->rejections().summary() << "\n";
}

}  // namespace covtrack::cli
