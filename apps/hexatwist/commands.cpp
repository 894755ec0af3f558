// Every subcommand of the tool, registered in the order `--help` lists them.
#include "cli_common.hpp"

namespace hexatwist::cli {

// The design commands (cmd_workspace.cpp, cmd_design.cpp, cmd_tolerance.cpp).
Command make_workspace_command(CLI::App& root);
Command make_design_command(CLI::App& root);
Command make_tolerance_command(CLI::App& root);

std::vector<Command> add_commands(CLI::App& app) {
  return {make_study_command(app),     make_simulate_command(app), make_dynamics_command(app),
          make_synth_command(app),     make_measure_command(app),  make_identify_command(app),
          make_workspace_command(app), make_design_command(app),   make_tolerance_command(app),
          make_stream_command(app),    make_ik_command(app),       make_fk_command(app),
          make_config_command(app),    make_linuxcnc_command(app), make_mjcf_command(app)};
}

}  // namespace hexatwist::cli
