#pragma once
// Each subcommand of `covtrack` registers itself on the app: one file per subcommand.
#include <CLI/CLI.hpp>

namespace covtrack::cli {

void add_echo_command(CLI::App& app);
void add_record_command(CLI::App& app);
void add_replay_command(CLI::App& app);
void add_regions_command(CLI::App& app);
void add_view_command(CLI::App& app);
void add_emulate_lenz_command(CLI::App& app);
void add_emulate_6dof_command(CLI::App& app);
void add_devices_command(CLI::App& app);
void add_keygen_command(CLI::App& app);
void add_render_tags_command(CLI::App& app);
void add_calibrate_fiducial_command(CLI::App& app);
void add_ar_command(CLI::App& app);

}  // namespace covtrack::cli
