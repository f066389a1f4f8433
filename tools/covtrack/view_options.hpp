#pragma once
// The options `covtrack view` and `covtrack ar` share about what they draw into and how
// often: --png, --video, --background, --duration, --fps, --confidence.
#include <string>

#include <CLI/CLI.hpp>

namespace covtrack::cli {

struct ViewOutputArgs {
  std::string png_path;
  std::string video_path;
  std::string background;
  double duration_s = 0;  // 0: until stopped (window), one frame (--png), the whole --log or 10 s (--video)
  double fps = 30;
  double confidence = 0;  // 0: the scene's
};

// `window_ends`: what ends the command's window, for --duration's help.
void add_view_output_options(CLI::App& command, ViewOutputArgs& args, const std::string& window_ends);

}  // namespace covtrack::cli
