#pragma once
// What covtrackd and covtrack share on the command line: --version, the exit codes in
// every --help, one-line usage errors ("covtrack echo: --count: must be 0 or more, got -1
// (try covtrack echo --help)") with exit code 2, and number checks whose errors read well.
#include <map>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "covtrack/program/exit_codes.hpp"

namespace covtrack::program {

// Adds --version and puts the exit codes (and `footer`, if any) under the --help of the
// program and of every subcommand added so far: call it after adding them.
void add_conventions(CLI::App& app, const std::string& footer = "");

// Parses the command line and runs the chosen subcommand's callback. Returns the exit code
// when the program is to end now (--help, --version, a usage error, a callback that threw
// CLI::RuntimeError(code)); nothing when all went well and the program goes on.
std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv);

// Number checks: "must be 0 or more", "must be more than 0", "must be between 0.5 and 0.9999".
CLI::Validator non_negative();
CLI::Validator positive();
CLI::Validator in_range(double min, double max);

// A choice among names that stand for enum values: --help lists the names ({unscented,
// linear}), not the values CLI11's CheckedTransformer shows; a wrong name is "must be one
// of unscented, linear, got x". Use with ->transform().
template <typename Enum>
CLI::Validator one_of(const std::map<std::string, Enum>& names) {
  std::string list;
  for (const auto& [name, value] : names) list += (list.empty() ? "" : ", ") + name;
  return CLI::Validator(
      [names, list](std::string& text) -> std::string {
        const auto chosen = names.find(text);
        if (chosen == names.end()) return "must be one of " + list + ", got " + text;
        text = std::to_string(static_cast<long long>(chosen->second));  // what CLI11 converts to the enum
        return {};
      },
      "{" + list + "}");
}

}  // namespace covtrack::program
