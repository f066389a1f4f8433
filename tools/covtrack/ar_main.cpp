// `covtrack-ar`: `covtrack ar`, in its own executable because OpenSceneGraph and OpenGL
// are needed by it alone (see delegated_command.hpp).
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "covtrack/program/command_line.hpp"

int main(int argc, char** argv) {
  CLI::App app{"covtrack: the scene's objects in 3-D over the camera view (see README.md)", "covtrack"};
  app.require_subcommand(1);
  covtrack::cli::add_ar_command(app);
  covtrack::program::add_conventions(app);
  return covtrack::program::parse_command_line(app, argc, argv).value_or(covtrack::program::kExitOk);
}
