// `covtrack ar SCENE`: the scene's objects drawn in 3-D over the camera view, where the
// tracking puts them, with their error regions and labels (client::ArView through the
// OpenSceneGraph adapter, covtrack::ar::ArScene). Poses come from the scene's values, the
// daemon's streams (--live) or a recording (--log), as for `covtrack view`. Output: a
// window, or one PNG (--png) or a video (--video) drawn off screen.
#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/videoio.hpp>

#include <fmt/format.h>

#include "commands.hpp"
#include "ar_models.hpp"
#include "covtrack/osg/ar_scene.hpp"
#include "covtrack/osg/ar_viewer.hpp"
#include "covtrack/program/command_line.hpp"
#include "region_drawing.hpp"
#include "regions_report.hpp"
#include "scene_ar_view.hpp"
#include "stop_signal.hpp"
#include "view_background.hpp"
#include "view_labels.hpp"
#include "view_source.hpp"
#include "view_video.hpp"

namespace covtrack::cli {
namespace {

struct ArArgs {
  std::string scene_path;
  ViewSourceArgs source;
  std::string png_path;
  std::string video_path;
  std::string background;
  double duration_s = 0;  // as for `covtrack view`
  double fps = 30;
  double confidence = 0;
  bool regions = true;
};

int run_ar(const ArArgs& args) {
  const auto fail_with = [](const std::string& message, int code) {
    std::cerr << "covtrack ar: " << message << "\n";
    return code;
  };
  const bool window = args.png_path.empty() && args.video_path.empty();
  std::optional<VideoFormat> video_format;
  if (!args.video_path.empty() && !(video_format = video_format_for(args.video_path)))
    return fail_with(fmt::format("--video {}: name it .mp4 (H.264) or .webm (VP9), formats browsers play",
                                 args.video_path), program::kExitUsageError);
  const auto model = load_regions_model(args.scene_path, args.confidence);
  if (!model) return fail_with(model.error().message, 2);
  const cv::Size size(model->camera.width_px, model->camera.height_px);
  auto view = scene_ar_view(*model, size);
  if (!view) return fail_with(fmt::format("{}: {}", args.scene_path, view.error().message), 2);

  ar::ArSceneOptions options;
  options.draw_regions = args.regions;
  ar::ArScene scene(model->camera, options);
  for (std::size_t i = 0; i < model->scene.objects.size(); ++i) {
    auto levels = ar_models(model->scene.objects[i], i);
    if (!levels) return fail_with(fmt::format("{}: {}", args.scene_path, levels.error().message), 2);
    scene.add_object(std::move(*levels));
  }
  auto viewer = ar::ArViewer::open(scene, window ? ar::ArViewer::Output::window : ar::ArViewer::Output::offscreen);
  if (!viewer) return fail_with(viewer.error().message, program::kExitRuntimeError);

  auto source = ViewSource::open(*model, args.source, "covtrack ar");
  if (!source) return fail_with(source.error().message, source.error().exit_code);
  ViewSource& src = **source;
  std::string warning;
  ViewBackground background(args.background, size, warning);
  if (background.camera_unavailable()) return fail_with(warning, program::kExitRuntimeError);
  std::optional<cv::VideoWriter> video;
  if (!args.video_path.empty()) {
    auto opened = open_video(args.video_path, *video_format, args.fps, size);
    if (!opened) return fail_with(opened.error().message, program::kExitRuntimeError);
    video.emplace(std::move(*opened));
  }

  install_stop_signals();
  src.announce();
  // As `covtrack view`: a video of a log covers all of it, else 10 s; offline into a file
  // frames are drawn at their scene or log times without waiting.
  const double duration_s = args.duration_s > 0 ? args.duration_s : (video && !src.log() ? 10.0 : 0.0);
  const bool virtual_clock = !src.live() && !window;
  const auto start = std::chrono::steady_clock::now();
  const auto period = std::chrono::duration<double>(1.0 / args.fps);
  std::vector<std::string> texts(model->scene.objects.size());
  for (long frame_index = 0;; ++frame_index) {
    double elapsed_s = frame_index * period.count();
    if (!virtual_clock) {
      std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(frame_index * period));
      elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    const auto now = src.advance(elapsed_s);
    if (!now) return fail_with(now.error().message, 2);
    const bool last = stop_requested() || (duration_s > 0 && elapsed_s >= duration_s - 1e-9) || src.finished();
    if (auto r = view->update(src.graph(), *now); !r) return fail_with(fmt::format("{}: {}", args.scene_path, r.error().message), 2);
    // --png takes its one frame at the end of --duration.
    if (!args.png_path.empty() && !last && duration_s > 0) continue;

    const client::ArFrame& frame = view->frame();
    for (std::size_t i = 0; i < texts.size(); ++i) texts[i] = label_text(model->scene.objects[i].name, frame.objects[i].regions);
    // A log's own camera frames are the background unless --background names another.
    cv::Mat image;
    if (src.log() && args.background.empty())
      if (const cv::Mat& f = src.log()->image(warning); !f.empty()) image = fit_to_view(f, size);
    if (image.empty()) image = background.next(warning);
    if (!warning.empty()) {
      std::cerr << "covtrack ar: " << warning << "\n";
      warning.clear();
    }
    scene.set_video(image);
    scene.update(frame, texts);
    const bool open = (*viewer)->frame();
    if (!args.png_path.empty()) {
      if (auto r = write_png((*viewer)->image(), args.png_path); !r) return fail_with(r.error().message, 1);
      src.report_rejections();
      return 0;
    }
    if (video) video->write((*viewer)->image());
    if (!open || last) break;
  }
  src.report_rejections();
  return 0;
}

}  // namespace

void add_ar_command(CLI::App& app) {
  auto args = std::make_shared<ArArgs>();
  auto* cmd = app.add_subcommand("ar", "Draw the objects in 3-D over the camera view, with their error regions");
  cmd->add_option("SCENE", args->scene_path, "Scene file (config/scene_schema.md); an object's `model` is its 3-D model")
      ->required();
  cmd->add_flag("--live", args->source.live, "Tracked transforms from the daemon's streams, not the scene's values");
  cmd->add_option("--lcm-url,-u", args->source.lcm_url, "LCM URL for --live (default: $LCM_DEFAULT_URL or LCM's)");
  cmd->add_option("--log", args->source.log_path, "Follow a recorded session (LCM log) at its own time");
  cmd->add_option("--speed,-s", args->source.speed, "Speed factor of --log")
      ->capture_default_str()
      ->check(program::in_range(0.01, 1000.0));
  cmd->add_option("--png", args->png_path, "Draw off screen, write one frame (at the end of --duration, if given) and exit");
  cmd->add_option("--video", args->video_path, "Draw off screen into this video file: FILE.mp4 (H.264) or FILE.webm (VP9)");
  cmd->add_option("--background", args->background,
                  "#rrggbb, an image file, a video file (looped) or camera:N (default with --log: the log's camera "
                  "frames, if it has any)");
  cmd->add_option("--duration,-d", args->duration_s,
                  "Seconds to run (default: until the window closes; for --video the whole --log, else 10); offline "
                  "(no --live) into a file, scene or log seconds drawn without waiting")
      ->check(program::non_negative());
  cmd->add_option("--fps", args->fps, "Frames per second")->capture_default_str()->check(program::in_range(0.1, 240.0));
  cmd->add_option("--confidence", args->confidence, "Confidence of the regions (default: the scene's)")
      ->check(program::in_range(0.5, 0.9999));
  cmd->add_flag("!--no-regions", args->regions, "Draw the objects and labels only, not their error regions");
  cmd->callback([args] {
    if (const int code = run_ar(*args); code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace covtrack::cli
