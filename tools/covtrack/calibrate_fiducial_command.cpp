// `covtrack calibrate-fiducial`: fits one camera's corner noise model from frames of a
// rigid board of tags (a tag bundle of the device's config) moved in front of it, so that
// the board's tags agree with each other within their covariances; writes the model as a
// file the device reads with `corner_calibration` (board_calibration.hpp).
#include <algorithm>
#include <chrono>
#include <ctime>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <fmt/ranges.h>

#include "board_calibration.hpp"
#include "commands.hpp"
#include "covtrack/program/command_line.hpp"
#include "fiducial_config.hpp"
#include "frame_source.hpp"

namespace covtrack::cli {
namespace {

struct CalibrateArgs {
  std::string config, device, board, source, out;
  int max_frames = 2000;
};

constexpr const char* kName = "covtrack calibrate-fiducial";

std::string model_file_text(const fiducial::CornerNoiseModel& m, const CalibrateArgs& a,
                            const fiducial::FiducialConfig& device, const fiducial::BoardFit& fit) {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char date[16];
  std::strftime(date, sizeof date, "%Y-%m-%d", std::gmtime(&now));
  std::string s = fmt::format(
      "# The corner noise model of the camera '{}' (device '{}' of {}), fitted by\n"
      "# `covtrack calibrate-fiducial` on {}: {} frames of board '{}', {} tag views ({} left out).\n"
      "# The board's tags' agreement (NEES of their known relative poses, 6 expected):\n"
      "# {:.2f} with the model before, {:.2f} with this one. Read with corner_calibration = \"<this file>\".\n"
      "[corner_model]\n",
      device.calibration, a.device, a.config, date, fit.frames_used, a.board, fit.residuals, fit.left_out,
      fit.before.mean_chi2, fit.after.mean_chi2);
  for (const auto& f : fiducial::corner_model_fields()) s += fmt::format("{} = {:.6g}\n", f.key, m.*f.value);
  return s;
}

void print_fit(const fiducial::BoardFit& fit, const fiducial::CornerNoiseModel& start) {
  fmt::print("{} tag views fitted from {} frames ({} left out as gross errors: residual NEES above 100); median edge "
             "blur {:.2f} px\n",
             fit.residuals, fit.frames_used, fit.left_out, fit.median_blur_px);
  if (fit.settled)
    fmt::print("settled in {} passes (the residuals rebuilt under each fit)\n", fit.passes);
  else
    fmt::print("not settled in {} passes: the last still moved a value by more than a tenth of its standard "
               "error (its fit is the one written)\n",
               fit.passes);
  fmt::print("  {:<34} {:>9} {:>9}\n", "", "before", "fitted");
  fmt::print("  {:<34} {:>9.4f} {:>9.4f} +- {:.4f}\n", "corner_scale_bias_per_blur", start.scale_bias_per_blur,
             fit.scale_bias_per_blur, fit.scale_bias_se);
  const auto factor = [](const char* what, double value, double se) {
    fmt::print("  {:<34} {:>9} {:>9.3f} +- {:.3f}\n", what, 1, value, se);
  };
  factor("independent corner noise (factor)", fit.independent_factor, fit.independent_se);
  factor("apparent-scale spread (factor)", fit.scale_factor, fit.scale_se);
  factor("edge placement spread (factor)", fit.edge_factor, fit.edge_se);
  fmt::print("  (edge turn and white-cell shift residual: kept as configured)\n");
  fmt::print("residual NEES of the fitted tag views: {:.2f} (8 expected)\n", fit.mean_residual_nees);
  fmt::print("the board's tags against each other: NEES of their known relative poses over {} tags (honest: "
             "mean 6, median 5.35, 1% above chi-square(6)'s 99% quantile)\n",
             fit.after.tags);
  for (const auto& [name, c] : {std::pair{"before", fit.before}, std::pair{"fitted", fit.after}})
    fmt::print("  {}: mean {:.2f}, median {:.2f}, {:.1f}% above\n", name, c.mean_chi2, c.median_chi2,
               100 * c.above_99);
}

int run_calibrate(const CalibrateArgs& a) {
  auto device = fiducial::read_config_device(a.config, a.device);
  if (!device) return fmt::print(stderr, "{}: {}\n", kName, device.error().message), 2;
  const auto board = std::find_if(device->bundles.begin(), device->bundles.end(),
                                  [&](const fiducial::TagBundle& b) { return b.name == a.board; });
  if (board == device->bundles.end()) {
    std::vector<std::string> names;
    for (const auto& b : device->bundles) names.push_back(b.name);
    return fmt::print(stderr, "{}: device '{}' has no bundle '{}' (its bundles: {})\n", kName, a.device, a.board,
                      names.empty() ? std::string("none: declare the board as [[devices.") + a.device + ".bundles]]"
                                    : fmt::format("{}", fmt::join(names, ", "))),
           2;
  }
  auto camera = load_camera(device->calibration);
  if (!camera) return fmt::print(stderr, "{}: {}\n", kName, camera.error().message), 2;
  auto detector = fiducial::TagDetector::create(device->detector);
  if (!detector) return fmt::print(stderr, "{}: {}\n", kName, detector.error().message), 2;
  const std::string source_name = a.source.empty() ? device->source : a.source;
  auto source = fiducial::open_frame_source(source_name, false);
  if (!source) return fmt::print(stderr, "{}: {}\n", kName, source.error().message), 2;

  std::vector<fiducial::BoardFrame> frames;
  int read = 0, damaged = 0;
  cv::Mat gray;
  while (read < a.max_frames) {
    auto frame = (*source)->next();
    if (!frame) return fmt::print(stderr, "{}: {}: {}\n", kName, source_name, frame.error().message), 1;
    if (frame->kind == fiducial::FrameRead::Kind::End) break;
    ++read;
    if (frame->kind == fiducial::FrameRead::Kind::Damaged) {
      ++damaged;
      fmt::print(stderr, "{}: damaged frame '{}': {}; skipped\n", kName, frame->name, frame->problem);
      continue;
    }
    fiducial::to_gray8(frame->image, gray);
    if (gray.cols != camera->width_px || gray.rows != camera->height_px)
      return fmt::print(stderr, "{}: '{}': frame is {}x{} but the calibration '{}' is for {}x{}\n", kName,
                        frame->name.empty() ? source_name : frame->name, gray.cols, gray.rows, device->calibration,
                        camera->width_px, camera->height_px),
             2;
    frames.push_back(fiducial::find_board(gray, **detector, *board));
  }
  const auto with_three = std::count_if(frames.begin(), frames.end(), [](const auto& f) { return f.size() >= 3; });
  fmt::print("{}: {} frames read from {} ({} damaged), {} with three or more of board '{}''s {} tags\n", kName, read,
             source_name, damaged, with_three, a.board, board->tags.size());
  auto fit = fiducial::fit_board_calibration(*camera, *board, frames, device->noise, device->ambiguity_chi2);
  if (!fit) return fmt::print(stderr, "{}: {}\n", kName, fit.error().message), 1;
  print_fit(*fit, device->noise);
  std::ofstream out(a.out);
  out << model_file_text(fit->model, a, *device, *fit);
  out.close();
  if (!out) return fmt::print(stderr, "{}: cannot write '{}'\n", kName, a.out), 1;
  fmt::print("wrote {}: use it with corner_calibration = \"{}\" in [devices.{}] (relative to the config's folder)\n",
             a.out, a.out, a.device);
  return 0;
}

}  // namespace

void add_calibrate_fiducial_command(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate-fiducial",
      "fit a camera's corner noise model from frames of a rigid board of tags (a tag bundle of the device) "
      "moved in front of it; writes a file the device reads with corner_calibration");
  cmd->add_option("config", args->config, "the covtrackd config declaring the device and its board")->required();
  cmd->add_option("--device", args->device, "the fiducial device (its camera calibration, family, detector)")
      ->required();
  cmd->add_option("--board", args->board, "the bundle to use as the board (its [[bundles]] name)")->required();
  cmd->add_option("--source", args->source, "frames to read instead of the device's source (images: a "
                                            "pattern such as frames/frame_%04d.png; or a video file)");
  cmd->add_option("--out,-o", args->out, "the corner model file to write")->required();
  cmd->add_option("--max-frames,-n", args->max_frames, "read at most this many frames")
      ->capture_default_str()->check(program::in_range(1, 1000000));
  cmd->callback([args] {
    const int rc = run_calibrate(*args);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace covtrack::cli
