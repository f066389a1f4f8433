#pragma once
// Subcommands that live in a sibling executable. `covtrack regions`, `view` and
// `render-tags` need OpenCV's image and video I/O, whose libraries pull in some 250 shared
// objects and a second of start-up; kept out of `covtrack` itself, echo, record, replay
// and the emulators start at once. The user still types one command: `covtrack view ...`
// runs `covtrack-vision view ...` from the same folder, with the same arguments.
#include <string>

#include <CLI/CLI.hpp>

namespace covtrack::cli {

void add_delegated_command(CLI::App& app, const std::string& name, const std::string& description,
                           const std::string& executable);

}  // namespace covtrack::cli
