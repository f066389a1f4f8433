// `covtrack keygen FILE`: a new shared key for authenticated messages (docs/authentication.md).
#include <iostream>

#include "commands.hpp"
#include "covtrack/program/command_line.hpp"
#include "covtrack/protocol/message_auth.hpp"

namespace covtrack::cli {

void add_keygen_command(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("keygen", "make a shared key file for authenticated messages (mode 0600)");
  cmd->add_option("FILE", *path, "key file to create (an existing file is never overwritten)")->required();
  cmd->callback([path] {
    if (auto written = write_new_auth_key(*path); !written) {
      std::cerr << "covtrack keygen: " << written.error().message << "\n";
      throw CLI::RuntimeError(program::kExitRuntimeError);
    }
    std::cerr << "covtrack keygen: wrote a new key to " << *path
              << "; give it to covtrackd ([auth] key_file) and to the clients (--key-file or $" << kKeyFileVariable
              << "), and keep it from others\n";
  });
}

}  // namespace covtrack::cli
