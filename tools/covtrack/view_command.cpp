// `covtrack view SCENE`: every object's registration error drawn over the camera view,
// from the scene's fixed values, or from the daemon's streams (--live), or from a
// recorded session at its own time (--log); tracked edges grow with report age, so
// latency shows as error. Output: a window when a display exists, else one PNG (--png)
// or a video (--video). In the window, or by scripted clicks, a user selects objects
// (selection_input.hpp).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/highgui.hpp>
#include <opencv2/videoio.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "commands.hpp"
#include "covtrack/program/command_line.hpp"
#include "region_drawing.hpp"
#include "regions_report.hpp"
#include "selection_input.hpp"
#include "stop_signal.hpp"
#include "view_background.hpp"
#include "view_clock.hpp"
#include "view_log.hpp"
#include "view_options.hpp"
#include "view_source.hpp"
#include "view_video.hpp"
#include "view_widgets.hpp"

namespace covtrack::cli {
namespace {

struct ViewArgs {
  std::string scene_path;
  ViewSourceArgs source;
  ViewOutputArgs output;
  SelectionArgs selection;
  client::ProjectionMethod method = client::ProjectionMethod::unscented;
};

// One line per tracked transform: where its value comes from and how old it is.
std::vector<std::string> legend_lines(const RegionsModel& model, const LatestReport& latest_report,
                                      const FrameMismatches& mismatches, std::int64_t now) {
  std::vector<std::string> lines = {
      fmt::format("{:.0f}% regions: ellipses blue, outer green, inner white", 100 * model.confidence)};
  for (const scene::SceneTransform& t : model.scene.transforms) {
    if (!t.stream) continue;
    std::string state = "fixed scene value";
    if (latest_report) {
      const auto latest = latest_report(*t.stream);
      state = latest ? fmt::format("{} {:.0f} ms old", to_string(latest->status), latest->age_s(now) * 1e3)
                     : std::string("no report: LOST");
      if (const auto parent = mismatches.reported_parent(*t.stream))
        state = fmt::format("not used: reports in frame '{}', not '{}'", *parent, t.parent);
    }
    lines.push_back(fmt::format("{} -> {} [{}]: {}", t.parent, t.child, t.stream->key(), state));
  }
  return lines;
}

// The scene's tracked pointer on the screen with its error: none without one, unusable
// (lost) when its transform is not known now.
std::optional<client::Pointer> tracked_pointer(const RegionsModel& model, const RegionsReport& report) {
  if (!model.scene.pointer) return std::nullopt;
  if (!report.pointer_tip) return client::Pointer{client::Vec2::Zero(), {}, true};
  return client::pointer_from_projection(*report.pointer_tip, report.confidence);
}

// What the pointer selects now, for the legend.
std::string pointer_line(const RegionsReport& report, const WidgetFrame& w) {
  if (!w.pointer) return {};
  if (w.pointer->lost) return "pointer: no usable position, selects nothing";
  const auto& s = w.selection;
  const std::string head = "pointer (yellow p=0, red p=1): ";
  if (!w.preselect) return head + "preselection off";
  if (!s.selected) return head + "selects nothing";
  const auto named = [&](int object) {
    const auto i = static_cast<std::size_t>(object);
    return fmt::format("{} p={:.2f}", report.objects[i].name, w.likelihoods[i]);
  };
  if (!s.ambiguous()) return head + "selects " + named(*s.selected);
  // Area likelihoods are per object (the share of the pointer's region on it), so two
  // can both be 1: list the candidates rather than one "best".
  constexpr std::size_t kListed = 3;
  std::vector<std::string> listed;
  for (std::size_t k = 0; k < std::min(kListed, s.candidates.size()); ++k) listed.push_back(named(s.candidates[k]));
  if (s.candidates.size() > kListed) listed.push_back("...");
  return head + fmt::format("pick a target of {}: {}", s.candidates.size(), fmt::join(listed, ", "));
}

// The legend's lines on selection: with a user, what was clicked; what the pointer selects.
std::vector<std::string> selection_lines(const RegionsReport& report, const WidgetFrame& w) {
  std::vector<std::string> lines;
  if (!w.technique.empty()) {
    const std::string clicked = w.clicked ? report.objects[static_cast<std::size_t>(*w.clicked)].name : "nothing";
    lines.push_back(fmt::format("{} selection (t switches, p preselects): {} selected (orange)", w.technique, clicked));
  }
  if (std::string line = pointer_line(report, w); !line.empty()) lines.push_back(std::move(line));
  return lines;
}

int run_view(const ViewArgs& args) {
  const auto fail_with = [](const std::string& message, int code) {
    std::cerr << "covtrack view: " << message << "\n";
    return code;
  };
  const bool window = args.output.png_path.empty() && args.output.video_path.empty();
  const auto video_format = args.output.video_path.empty() ? Result<VideoFormat>{} : video_format_for(args.output.video_path);
  if (!video_format) return fail_with(video_format.error().message, program::kExitUsageError);
  if (window && !std::getenv("DISPLAY"))
    return fail_with("no display (DISPLAY is not set): use --png FILE or --video FILE", 2);
  const auto model = load_regions_model(args.scene_path, args.output.confidence);
  if (!model) return fail_with(model.error().message, 2);
  auto widgets = ViewWidgets::create(model->scene);
  if (!widgets) return fail_with(fmt::format("{}: {}", args.scene_path, widgets.error().message), 2);
  // A user selects in the window, or a script (--click) does.
  auto input = SelectionInput::create(model->scene, model->camera, model->confidence, args.selection);
  if (!input) return fail_with(input.error().message, program::kExitUsageError);
  const bool with_user = window || !args.selection.clicks.empty();

  auto source = ViewSource::open(*model, args.source, "covtrack view");
  if (!source) return fail_with(source.error().message, source.error().exit_code);
  ViewSource& src = **source;

  const cv::Size size(model->camera.width_px, model->camera.height_px);
  std::string warning;
  ViewBackground background(args.output.background, size, warning);
  if (background.camera_unavailable()) return fail_with(warning, program::kExitRuntimeError);
  std::optional<cv::VideoWriter> video;
  if (!args.output.video_path.empty()) {
    auto opened = open_video(args.output.video_path, *video_format, args.output.fps, size);
    if (!opened) return fail_with(opened.error().message, program::kExitRuntimeError);
    video.emplace(std::move(*opened));
  }
  if (window) {
    // GUI_NORMAL: no toolbar above the image (Qt's), so the image starts at the window's corner.
    cv::namedWindow("covtrack view", cv::WINDOW_AUTOSIZE | cv::WINDOW_GUI_NORMAL);
    // Called from cv::waitKey, on this thread; the window shows the image 1:1.
    cv::setMouseCallback("covtrack view", [](int event, int x, int y, int, void* user) {
      auto& in = *static_cast<SelectionInput*>(user);
      if (event == cv::EVENT_MOUSEMOVE) in.move_mouse(client::Vec2(x, y));
      else if (event == cv::EVENT_LBUTTONDOWN) in.press_mouse(client::Vec2(x, y));
    }, &*input);
  }

  install_stop_signals();
  src.announce();
  // A video of a log covers all of it; one of a scene or of live streams, 10 s.
  const double duration_s = args.output.duration_s > 0 ? args.output.duration_s : (video && !src.log() ? 10.0 : 0.0);
  const ViewClock clock(args.output.fps, !src.live() && !window);
  for (long frame_index = 0;; ++frame_index) {
    const double elapsed_s = clock.frame_time_s(frame_index);
    const auto now = src.advance(elapsed_s);
    if (!now) return fail_with(now.error().message, 2);
    const bool last = stop_requested() || (duration_s > 0 && elapsed_s >= duration_s - 1e-9) || src.finished();
    const auto report = compute_regions(*model, src.graph(), *now, args.method);
    if (!report) return fail_with(fmt::format("{}: {}", args.scene_path, report.error().message), 2);
    // Every frame feeds the Level-of-Error hysteresis and takes the clicks due, even
    // those --png does not write.
    std::optional<SelectionState> user;
    if (with_user) user = input->frame(tracked_pointer(*model, *report), selectables_of(*report), elapsed_s, std::cout);
    const WidgetFrame widget_frame = widgets->update(*report, size, user ? &*user : nullptr);
    // --png takes its one frame at the end of --duration (live streams have arrived by then).
    if (!args.output.png_path.empty() && !last && duration_s > 0) continue;

    cv::Mat image = src.picture(background, args.output.background.empty(), size, warning);
    if (!warning.empty()) {
      std::cerr << "covtrack view: " << warning << "\n";
      warning.clear();
    }
    auto lines = legend_lines(*model, src.latest_report(), src.mismatches(), *now);
    for (std::string& line : selection_lines(*report, widget_frame)) lines.push_back(std::move(line));
    draw_regions(image, *report, &widget_frame, legend_height_px(lines.size(), image.rows));
    draw_legend(image, lines);

    if (!args.output.png_path.empty()) {
      if (auto r = write_png(image, args.output.png_path); !r) return fail_with(r.error().message, 1);
      src.report_rejections();
      return 0;
    }
    if (video) video->write(image);
    if (window) {
      cv::imshow("covtrack view", image);
      const int key = cv::waitKey(1);
      if (key == 'q' || key == 27 || cv::getWindowProperty("covtrack view", cv::WND_PROP_VISIBLE) < 1) break;
      if (key >= 0) input->press_key(key & 0xff);
    }
    if (last) break;
  }
  src.report_rejections();
  return 0;
}

}  // namespace

void add_view_command(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand("view", "Draw the objects' error regions over the camera view");
  cmd->add_option("SCENE", args->scene_path, "Scene file (config/scene_schema.md)")->required();
  add_view_source_options(*cmd, args->source);
  add_view_output_options(*cmd, args->output, "q/Esc/Ctrl-C");
  add_selection_options(*cmd, args->selection);
  const std::map<std::string, client::ProjectionMethod> methods = {
      {"unscented", client::ProjectionMethod::unscented}, {"linear", client::ProjectionMethod::linear}};
  cmd->add_option("--method", args->method, "Vertex projection: unscented or linear")
      ->transform(program::one_of(methods));
  cmd->callback([args] {
    if (const int code = run_view(*args); code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace covtrack::cli
