#include "delegated_command.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <vector>

#include "covtrack/program/exit_codes.hpp"

namespace covtrack::cli {

void add_delegated_command(CLI::App& app, const std::string& name, const std::string& description,
                           const std::string& executable) {
  auto* cmd = app.add_subcommand(name, description + " (see: covtrack " + name + " --help)");
  cmd->prefix_command();  // every argument, --help included, goes to the other executable
  cmd->set_help_flag();
  cmd->callback([cmd, name, executable] {
    std::error_code ec;
    const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
    const std::string path = (self.parent_path() / executable).string();
    std::vector<std::string> args = {path, name};
    for (const std::string& a : cmd->remaining()) args.push_back(a);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(path.c_str(), argv.data());
    std::cerr << "covtrack " << name << ": cannot run " << path << ": " << std::strerror(errno)
              << " (it is built and installed next to covtrack)\n";
    throw CLI::RuntimeError(program::kExitRuntimeError);
  });
}

}  // namespace covtrack::cli
