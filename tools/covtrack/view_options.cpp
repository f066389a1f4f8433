#include "view_options.hpp"

#include "covtrack/program/command_line.hpp"

namespace covtrack::cli {

void add_view_output_options(CLI::App& command, ViewOutputArgs& args, const std::string& window_ends) {
  command.add_option("--png", args.png_path, "Write one frame (at the end of --duration, if given) and exit");
  command.add_option("--video", args.video_path,
                     "Write the frames to this video file: FILE.mp4 (H.264) or FILE.webm (VP9), which browsers play");
  command.add_option("--background", args.background,
                     "#rrggbb, an image file, a video file (looped) or camera:N (default with --log: the "
                     "log's camera frames, if it has any)");
  command.add_option("--duration,-d", args.duration_s,
                     "Seconds to run (default: until " + window_ends +
                         "; for --video the whole --log, else 10); offline (no --live) into a file, scene or log "
                         "seconds rendered without waiting")
      ->check(program::non_negative());
  command.add_option("--fps", args.fps, "Frames per second")->capture_default_str()->check(program::in_range(0.1, 240.0));
  command.add_option("--confidence", args.confidence, "Confidence of the regions (default: the scene's)")
      ->check(program::in_range(0.5, 0.9999));
}

}  // namespace covtrack::cli
