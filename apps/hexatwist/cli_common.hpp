// SPDX-License-Identifier: BSD-3-Clause
// Shared pieces of the hexatwist command-line tool: exit codes, input parsing, model loading.
#pragma once

#include <CLI/CLI.hpp>

#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hexatwist/hexatwist.hpp"

namespace hexatwist::cli {

/// Exit codes of the tool.
enum ExitCode : int {
  kExitOk = 0,
  kExitBadInput = 2,       ///< malformed input, bad configuration, unreadable file
  kExitOutOfLimit = 3,     ///< a pose outside a limit, or a forward-kinematics failure
  kExitOutputFailed = 4,   ///< an output file or figure could not be written
  kExitNotIdentified = 5,  ///< identify: the data do not determine the parameters, or the solver did not converge
  kExitInterrupted = 6,    ///< SIGINT, SIGTERM or SIGHUP ended the run; it was rolled back (signals.hpp)
};

/// A failure the tool reports as one line on stderr with its exit code.
class ExitError : public std::runtime_error {
 public:
  ExitError(int code, const std::string& message) : std::runtime_error(message), code_(code) {}
  int code() const noexcept { return code_; }

 private:
  int code_;
};

/// Text typed by the user as it may appear inside a one-line message: control characters escaped.
std::string printable(std::string_view text);

/// Options every command that needs a platform shares.
struct ModelOptions {
  std::string config;               ///< YAML file; empty = embedded seed platform
  const char* option = "--config";  ///< how messages name the argument
};

/// Adds --config to a subcommand.
void add_model_options(CLI::App& app, ModelOptions& opts);

/// For a report's header after the platform's name: "" when the configuration gives its drives and
/// load, else " (servo, load: the seed's defaults, not in the file)" naming the sections it leaves out.
std::string defaults_note(const Config& config);

/// More targets on the platform besides the observation point, "x,y,z;x,y,z" [mm, P] as `option`
/// takes them (empty: none), in metres; ExitError(2) naming the option for a malformed list, a
/// coordinate of 10 m or more, or more than kMaxTargets targets with the observation point.
std::vector<Vector3d> targets_option(const std::string& text, const char* option = "--targets-mm");

/// "1 file", "2 files": a count and its noun (plural by an added s).
std::string counted(std::size_t n, std::string_view noun);

/// The strategy `text` names (parse_strategy); ExitError(2) naming `option` for any other text.
Strategy strategy_option(const std::string& text, const char* option = "--strategy");

/// Loads the model named by --config (or the embedded default); errors become ExitError(2).
Model load_model_from(const ModelOptions& opts);

/// Loads the whole configuration (platform, servo, load, simulation, study) the same way.
Config load_config_from(const ModelOptions& opts);

/// Reads a whole file of at most `max_bytes` (hexatwist::read_text_file: kMaxDataBytes for data,
/// kMaxConfigBytes for a configuration); a missing, unreadable, directory or longer path becomes
/// ExitError(2) naming `option`.
std::string read_text_file(const std::string& path, const std::string& option, const std::string& what,
                           std::size_t max_bytes = kMaxDataBytes);

/// Writes `text` to standard output and flushes it; ExitError(4) if it could not be written whole
/// (a full disk, a closed pipe).
void write_stdout(std::string_view text);

/// Name of the platform source for messages.
std::string model_source(const ModelOptions& opts);

/// Parses exactly `count` comma-separated finite numbers given to option `option`; `what`
/// describes them for the error message.
std::vector<double> parse_numbers(const std::string& text, std::size_t count, const std::string& option,
                                  const std::string& what);

/// One value for every leg, or six comma-separated, each checked against [lo, hi] in the option's
/// units (`what` says them for the message) and multiplied by `scale` to SI.
Vector6d per_leg_option(const std::string& text, const char* option, const std::string& what, double lo, double hi,
                        double scale);

/// The legs' temperatures of `--temperature-c` [degC] (one or six; empty: the reference, NaN).
/// ExitError(2) for a value outside the plausible range, or any value for a `model` whose legs do
/// not expand (it would change nothing).
Vector6d temperature_option(const std::string& text, const Model& model);

/// `--range X_M,ROT_DEG` into `run`'s translation [m] and rotation [rad]: 0 to 10 m and 0 to 90 deg,
/// not both 0 (ExitError(2) naming the option).
void range_option(const std::string& text, StationsSpec& run);

/// The legs' warm-up over a run of `--temperature-rise-k` [K] (one or six, each within
/// +-kMaxTemperatureRise; empty: none), for synth's real platform and the study's leg effects.
/// ExitError(2) for a value out of range, or any for a `model` (may be null) whose legs do not expand.
Vector6d temperature_rise_option(const std::string& text, const Model* model);

/// Help text of `--temperature-c`.
inline constexpr const char* kTemperatureHelp =
    "Each leg's temperature [degC], one or six, for a configuration with leg_effects (their thermal "
    "expansion); default: its reference temperature";

/// ExitError(2) "OPTION VALUE: expected EXPECTED" unless `ok`: the check of a number option's
/// range, sign and finiteness (NaN and infinities never pass: `ok` must be false for them).
void check_option(bool ok, std::string_view option, double value, std::string_view expected);

/// Parses "x,y,z,roll,pitch,yaw" in m and degrees into a pose [m, rad].
Pose parse_pose_m_deg(const std::string& text, const std::string& option);

/// A rounding-level value (|v| < 1e-12) as 0, so that text output shows 0.0000, not -0.0000.
inline double tidy(double v) { return std::abs(v) < 1e-12 ? 0.0 : v; }

/// Writes a JSON object for a limit report (or null if none).
class JsonWriter;
void write_limit_json(JsonWriter& json, const LimitReport& report);

/// Registers a subcommand; `run` is called when it was chosen and returns the exit code.
struct Command {
  CLI::App* app;
  std::function<int()> run;
};
Command make_ik_command(CLI::App& root);
Command make_fk_command(CLI::App& root);
Command make_compare_command(CLI::App& root);
Command make_config_command(CLI::App& root);
Command make_study_command(CLI::App& root);
Command make_simulate_command(CLI::App& root);
Command make_dynamics_command(CLI::App& root);
Command make_stream_command(CLI::App& root);
Command make_synth_command(CLI::App& root);
Command make_measure_command(CLI::App& root);
Command make_identify_command(CLI::App& root);
Command make_linuxcnc_command(CLI::App& root);
Command make_mjcf_command(CLI::App& root);

/// Registers every subcommand on the root app, in the order --help lists them.
std::vector<Command> add_commands(CLI::App& app);

}  // namespace hexatwist::cli
