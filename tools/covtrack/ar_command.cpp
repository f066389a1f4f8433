// `covtrack ar SCENE`: the scene's objects drawn in 3-D over the camera view, where the
// tracking puts them, with their error regions and labels (client::ArView through the
// OpenSceneGraph adapter, covtrack::ar::ArScene). Poses come from the scene's values, the
// daemon's streams (--live) or a recording (--log), as for `covtrack view`. Output: a
// window, or one PNG (--png) or a video (--video) drawn off screen.
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/videoio.hpp>

#include <fmt/format.h>

#include "commands.hpp"
#include "ar_models.hpp"
#include "ar_selection.hpp"
#include "covtrack/osg/ar_scene.hpp"
#include "covtrack/osg/ar_viewer.hpp"
#include "covtrack/program/command_line.hpp"
#include "region_drawing.hpp"
#include "regions_report.hpp"
#include "scene_ar_view.hpp"
#include "stop_signal.hpp"
#include "view_background.hpp"
#include "view_clock.hpp"
#include "view_labels.hpp"
#include "view_options.hpp"
#include "view_source.hpp"
#include "view_video.hpp"

namespace covtrack::cli {
namespace {

struct ArArgs {
  std::string scene_path;
  ViewSourceArgs source;
  ViewOutputArgs output;
  bool regions = true;
  SelectionArgs selection;
};

int run_ar(const ArArgs& args) {
  const auto fail_with = [](const std::string& message, int code) {
    std::cerr << "covtrack ar: " << message << "\n";
    return code;
  };
  const bool window = args.output.png_path.empty() && args.output.video_path.empty();
  const auto video_format = args.output.video_path.empty() ? Result<VideoFormat>{} : video_format_for(args.output.video_path);
  if (!video_format) return fail_with(video_format.error().message, program::kExitUsageError);
  const auto model = load_regions_model(args.scene_path, args.output.confidence);
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
  auto input = SelectionInput::create(model->scene, model->camera, model->confidence, args.selection);
  if (!input) return fail_with(input.error().message, program::kExitUsageError);
  osg::ref_ptr<ArSelection> selection = new ArSelection(*model, std::move(*input));
  auto viewer = ar::ArViewer::open(scene, window ? ar::ArViewer::Output::window : ar::ArViewer::Output::offscreen);
  if (!viewer) return fail_with(viewer.error().message, program::kExitRuntimeError);
  (*viewer)->add_event_handler(selection.get());

  auto source = ViewSource::open(*model, args.source, "covtrack ar");
  if (!source) return fail_with(source.error().message, source.error().exit_code);
  ViewSource& src = **source;
  std::string warning;
  ViewBackground background(args.output.background, size, warning);
  if (background.camera_unavailable()) return fail_with(warning, program::kExitRuntimeError);
  std::optional<cv::VideoWriter> video;
  if (!args.output.video_path.empty()) {
    auto opened = open_video(args.output.video_path, *video_format, args.output.fps, size);
    if (!opened) return fail_with(opened.error().message, program::kExitRuntimeError);
    video.emplace(std::move(*opened));
  }

  install_stop_signals();
  src.announce();
  // As `covtrack view`: a video of a log covers all of it, else 10 s.
  const double duration_s = args.output.duration_s > 0 ? args.output.duration_s : (video && !src.log() ? 10.0 : 0.0);
  const ViewClock clock(args.output.fps, !src.live() && !window);
  std::vector<std::string> texts(model->scene.objects.size());
  for (long frame_index = 0;; ++frame_index) {
    const double elapsed_s = clock.frame_time_s(frame_index);
    const auto now = src.advance(elapsed_s);
    if (!now) return fail_with(now.error().message, 2);
    const bool last = stop_requested() || (duration_s > 0 && elapsed_s >= duration_s - 1e-9) || src.finished();
    if (auto r = view->update(src.graph(), *now); !r) return fail_with(fmt::format("{}: {}", args.scene_path, r.error().message), 2);
    // Every frame takes the clicks due, even those --png does not draw.
    const ar::SelectionDrawing selected = selection->frame(view->frame(), src.graph(), *now, elapsed_s, std::cout);
    // --png takes its one frame at the end of --duration.
    if (!args.output.png_path.empty() && !last && duration_s > 0) continue;

    const client::ArFrame& frame = view->frame();
    for (std::size_t i = 0; i < texts.size(); ++i) texts[i] = label_text(model->scene.objects[i].name, frame.objects[i].regions);
    cv::Mat image = src.picture(background, args.output.background.empty(), size, warning);
    if (!warning.empty()) {
      std::cerr << "covtrack ar: " << warning << "\n";
      warning.clear();
    }
    scene.set_video(image);
    scene.update(frame, texts, &selected);
    const bool open = (*viewer)->frame();
    if (!args.output.png_path.empty()) {
      if (auto r = write_png((*viewer)->image(), args.output.png_path); !r) return fail_with(r.error().message, 1);
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
  auto* cmd = app.add_subcommand("ar", "Draw the objects in 3-D over the camera view, with their error regions (in a window; "
                                             "off screen with --png or --video)");
  cmd->add_option("SCENE", args->scene_path, "Scene file (config/scene_schema.md); an object's `model` is its 3-D model")
      ->required();
  add_view_source_options(*cmd, args->source);
  add_view_output_options(*cmd, args->output, "the window closes, Esc or Ctrl-C");
  cmd->add_flag("!--no-regions", args->regions, "Draw the objects and labels only, not their error regions");
  add_selection_options(*cmd, args->selection);
  cmd->callback([args] {
    if (const int code = run_ar(*args); code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace covtrack::cli
