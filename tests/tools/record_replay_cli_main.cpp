// Stand-in for the `covtrack` binary with only `record` and `replay`, for trees where the
// rest of `covtrack` (echo, covtrack_client) does not build yet. Same command sources.
#include <CLI/CLI.hpp>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"covtrack record/replay (test build)", "covtrack"};
  app.require_subcommand(1);
  covtrack::cli::add_record_command(app);
  covtrack::cli::add_replay_command(app);
  CLI11_PARSE(app, argc, argv);
  return 0;
}
