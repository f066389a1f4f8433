// `covtrack-vision`: the subcommands of `covtrack` that need OpenCV's image and video I/O
// (see delegated_command.hpp). People run them as `covtrack regions`, `covtrack view`,
// `covtrack render-tags` and `covtrack calibrate-fiducial`.
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "covtrack/program/command_line.hpp"

int main(int argc, char** argv) {
  CLI::App app{"covtrack: scene error regions, the viewer, tag rendering and calibration (see README.md)", "covtrack"};
  app.require_subcommand(1);
  covtrack::cli::add_regions_command(app);
  covtrack::cli::add_view_command(app);
  covtrack::cli::add_render_tags_command(app);
  covtrack::cli::add_calibrate_fiducial_command(app);
  covtrack::program::add_conventions(app);
  return covtrack::program::parse_command_line(app, argc, argv).value_or(covtrack::program::kExitOk);
}
