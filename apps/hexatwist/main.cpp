// SPDX-License-Identifier: BSD-3-Clause
// hexatwist: twist-aware kinematics of lead-screw Stewart platforms, from the command line.
// This directory is the only code of the project that reads files and writes to the terminal.
#include <fmt/format.h>

#include <algorithm>

#include <cstdio>
#include <exception>
#include <iostream>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cli_common.hpp"
#include "hexatwist/version.hpp"
#include "signals.hpp"

namespace {

// Every failure is one line on stderr: control characters in a message (a newline in a value
// the user typed, or in a library message) are escaped.
void print_error(std::string_view prefix, std::string_view message) {
  std::string line(prefix);
  for (const char c : message) {
    const auto u = static_cast<unsigned char>(c);
    line += (u < 0x20 || u == 0x7f) ? fmt::format("\\x{:02x}", u) : std::string(1, c);
  }
  std::fprintf(stderr, "%s\n", line.c_str());
}

// The option of the command being run that sets the library's parameter `name`: --name, else
// --name-UNIT (tracker_noise is --tracker-noise-um, targets --targets-mm); null when it has none.
// The fields whose option has another name: the stations' ranges and approach, the design's volume
// orientation, the synthesis' zero and observation-point offsets.
const CLI::Option* option_for(const std::vector<hexatwist::cli::Command>& commands, std::string name) {
  if (name == "translation" || name == "rotation") name = "range";
  if (name == "approach") name = "both_sides";
  if (name == "volume_rpy") name = "volume_orientation";
  if (name == "zero_offset") name = "offsets";
  if (name == "observation_offset") name = "point_offset";
  std::replace(name.begin(), name.end(), '_', '-');
  const std::string flag = "--" + name;
  for (const hexatwist::cli::Command& c : commands) {
    if (!c.app->parsed()) continue;
    const CLI::Option* with_unit = nullptr;
    for (const CLI::Option* o : c.app->get_options())
      for (const std::string& l : o->get_lnames()) {
        if ("--" + l == flag) return o;
        if (with_unit == nullptr && ("--" + l).starts_with(flag + "-")) with_unit = o;
      }
    if (with_unit != nullptr) return with_unit;
  }
  return nullptr;
}

// How the command line names the library's parameter `name` in an error: "[--option]". The library
// states values in SI; when the option is typed in another unit (its name's suffix, its help's
// "[deg]"), what was typed is shown too: "; typed -1 deg [--clearance]".
std::string option_note(const std::vector<hexatwist::cli::Command>& commands, const std::string& name) {
  const CLI::Option* o = option_for(commands, name);
  if (o == nullptr) {
    std::string flag = "--" + name;
    std::replace(flag.begin(), flag.end(), '_', '-');
    return fmt::format(" [{}]", flag);
  }
  const std::string flag = "--" + o->get_lnames().front();
  if (o->count() == 0) return fmt::format(" [{}]", flag);
  // The unit it is typed in when not SI: its name's suffix (--noise-um, --lead-error-pct), else its
  // help's "[deg]" or "[mm, platform]" (the first word in the brackets).
  static const std::vector<std::pair<std::string, std::string>> suffixes{
      {"-ppm-per-k", "ppm/K"}, {"-n-per-um", "N/um"}, {"-pct", "%"},   {"-mm", "mm"},
      {"-um", "um"},           {"-deg", "deg"},       {"-ppm", "ppm"}, {"-urad", "urad"}};
  static const std::set<std::string> typed_units{"deg", "mm", "um", "%", "ppm", "ppm/K", "urad", "N/um"};
  std::string unit;
  for (const auto& [suffix, u] : suffixes)
    if (flag.ends_with(suffix)) {
      unit = u;
      break;
    }
  const std::string& help = o->get_description();
  for (std::size_t a = help.find('['); unit.empty() && a != std::string::npos; a = help.find('[', a + 1)) {
    const std::size_t b = help.find_first_of(",]", a);
    if (b != std::string::npos && typed_units.count(help.substr(a + 1, b - a - 1)))
      unit = help.substr(a + 1, b - a - 1);
  }
  if (unit.empty()) return fmt::format(" [{}]", flag);
  std::string typed;
  for (const std::string& r : o->results()) typed += (typed.empty() ? "" : ",") + r;
  return fmt::format("; typed {} {} [{}]", hexatwist::cli::printable(typed), unit, flag);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace hexatwist::cli;
  signals::install();
  CLI::App app{
      "hexatwist: twist-aware kinematics of lead-screw Stewart platforms.\n"
      "Poses are typed as x,y,z [m] and roll,pitch,yaw [deg] (R = Rz*Ry*Rx); all JSON output is SI (m, rad).\n"
      "Exit codes: 0 ok, 2 bad input, 3 pose outside a limit, numerical failure or (dynamics) a motor outside its "
      "envelope, 4 output not written, 5 identify: "
      "the data do not determine the parameters, 6 stopped by SIGINT, SIGTERM or SIGHUP (rolled back: nothing "
      "written)."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("hexatwist ") + std::string(hexatwist::kVersion));
  const std::vector<Command> commands = add_commands(app);
  // Help and version go to standard output like every result: a failed write is exit 4.
  const auto print_and_check = [&](const CLI::Error& e) {
    const int code = app.exit(e);
    std::cout.flush();
    if (!std::cout || std::fflush(stdout) != 0) {
      print_error("hexatwist: error: ", "cannot write to standard output");
      return static_cast<int>(kExitOutputFailed);
    }
    return code;
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return print_and_check(e);
  } catch (const CLI::CallForAllHelp& e) {
    return print_and_check(e);
  } catch (const CLI::CallForVersion& e) {
    return print_and_check(e);
  } catch (const CLI::ParseError& e) {
    // CLI11 reports an unknown subcommand as "a subcommand is required": name it instead. The
    // root takes no option with a value, so the first word that is not an option is the command.
    bool chosen = false;
    for (const Command& c : commands) chosen = chosen || c.app->parsed();
    for (int k = 1; k < argc && !chosen; ++k) {
      const std::string_view word = argv[k];
      if (word.starts_with("-")) continue;
      for (const Command& c : commands) chosen = chosen || c.app->get_name() == word;
      if (chosen) break;
      // The list is the commands' own, so that it names every one.
      std::string names;
      for (std::size_t n = 0; n < commands.size(); ++n)
        names += (n == 0 ? "" : n + 1 == commands.size() ? " or " : ", ") + commands[n].app->get_name();
      print_error("hexatwist: error: ",
                  fmt::format("unknown subcommand '{}'; expected {} (see --help)", printable(word), names));
      return kExitBadInput;
    }
    print_error("hexatwist: error: ", fmt::format("{} (see --help)", e.what()));
    return kExitBadInput;
  }
  try {
    for (const Command& c : commands)
      if (c.app->parsed()) {
        const int code = c.run();
        signals::stop_on_request();  // the outcome is decided: a signal now changes nothing
        return code;
      }
  } catch (const ExitError& e) {
    signals::stop_on_request();  // the run was rolled back; its error is the outcome
    print_error("hexatwist: error: ", e.what());
    return e.code();
  } catch (const hexatwist::ParameterError& e) {
    signals::stop_on_request();
    // The library names the parameter at fault; the command line names it as its option.
    print_error("hexatwist: error: ", fmt::format("{}{}", e.what(), option_note(commands, e.parameter())));
    return kExitBadInput;
  } catch (const hexatwist::Error& e) {
    signals::stop_on_request();
    print_error("hexatwist: error: ", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    signals::stop_on_request();
    print_error("hexatwist: internal error: ", e.what());
    return 1;
  }
  return kExitBadInput;
}
