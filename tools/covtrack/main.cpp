// `covtrack`: the command people use next to the daemon.
#include <CLI/CLI.hpp>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"covtrack: pose + covariance streams over LCM (see README.md)", "covtrack"};
  app.require_subcommand(1);
  covtrack::cli::add_echo_command(app);
  covtrack::cli::add_record_command(app);
  covtrack::cli::add_replay_command(app);
  covtrack::cli::add_render_tags_command(app);
  CLI11_PARSE(app, argc, argv);
  return 0;
}
