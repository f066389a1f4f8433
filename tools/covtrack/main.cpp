// `covtrack`: the command people use next to the daemon.
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "covtrack/program/command_line.hpp"
#include "delegated_command.hpp"

int main(int argc, char** argv) {
  CLI::App app{"covtrack: pose + covariance streams over LCM (see README.md)", "covtrack"};
  app.require_subcommand(1);
  covtrack::cli::add_echo_command(app);
  covtrack::cli::add_record_command(app);
  covtrack::cli::add_replay_command(app);
  covtrack::cli::add_delegated_command(app, "regions", "Screen error regions of a scene's objects (offline)",
                                       "covtrack-vision");
  covtrack::cli::add_delegated_command(app, "view", "Draw the objects' error regions over the camera view",
                                       "covtrack-vision");
  covtrack::cli::add_delegated_command(app, "render-tags", "Render AprilTags at known poses (images or video + truth)",
                                       "covtrack-vision");
  covtrack::cli::add_delegated_command(app, "calibrate-fiducial",
                                       "Fit a camera's corner noise model from frames of a board of tags",
                                       "covtrack-vision");
  covtrack::cli::add_delegated_command(app, "ar", "Draw the objects in 3-D over the camera view, with their error regions",
                                       "covtrack-ar");
  covtrack::cli::add_emulate_lenz_command(app);
  covtrack::cli::add_emulate_6dof_command(app);
  covtrack::cli::add_devices_command(app);
  covtrack::cli::add_keygen_command(app);
  covtrack::program::add_conventions(app);
  return covtrack::program::parse_command_line(app, argc, argv).value_or(covtrack::program::kExitOk);
}
