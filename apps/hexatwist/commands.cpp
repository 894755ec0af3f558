// SPDX-License-Identifier: BSD-3-Clause
// Every subcommand of the tool, registered in the order `--help` lists them.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "cli_common.hpp"

namespace hexatwist::cli {
namespace {

// CLI11 reads "-1" into an unsigned option as 2^64 - 1 (a seed, a count): every unsigned option
// takes a whole number >= 0 written as such, or is refused naming itself.
const CLI::Validator kWholeNumber(
    [](std::string& text) {
      std::uint64_t v = 0;
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
      if (text.empty() || ec != std::errc() || end != text.data() + text.size())
        return std::string("expected a whole number >= 0, got '") + printable(text) + "'";
      return std::string();
    },
    "", "whole number");

// No floating-point option means anything at NaN or an infinity (and an option whose absence is
// NaN would take a typed "nan" for absent): every one takes a finite number, or is refused naming
// itself.
const CLI::Validator kFiniteNumber(
    [](std::string& text) {
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (!text.empty() && end == text.c_str() + text.size() && !std::isfinite(v))
        return std::string("expected a finite number, got '") + printable(text) + "'";
      return std::string();
    },
    "", "finite number");

}  // namespace

// Where to measure (cmd_stations.cpp).
Command make_stations_command(CLI::App& root);
// The design commands (cmd_workspace.cpp, cmd_design.cpp, cmd_tolerance.cpp).
Command make_workspace_command(CLI::App& root);
Command make_design_command(CLI::App& root);
Command make_tolerance_command(CLI::App& root);

std::vector<Command> add_commands(CLI::App& app) {
  std::vector<Command> commands{make_study_command(app),     make_simulate_command(app),  make_dynamics_command(app),
                                make_synth_command(app),     make_measure_command(app),   make_identify_command(app),
                                make_stations_command(app),  make_workspace_command(app), make_design_command(app),
                                make_tolerance_command(app), make_stream_command(app),    make_ik_command(app),
                                make_fk_command(app),        make_config_command(app),    make_linuxcnc_command(app),
                                make_mjcf_command(app),      make_compare_command(app)};
  for (const Command& c : commands)
    for (CLI::Option* opt : c.app->get_options())
      if (opt->get_type_name() == "UINT")
        opt->check(kWholeNumber);
      else if (opt->get_type_name() == "FLOAT")
        opt->check(kFiniteNumber);
  return commands;
}

}  // namespace hexatwist::cli
