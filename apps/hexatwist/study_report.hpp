// SPDX-License-Identifier: BSD-3-Clause
// What `hexatwist study` and `hexatwist simulate` write: the terminal table, summary.json,
// summary.md, one CSV per test and strategy, and the figures.
#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hexatwist/hexatwist.hpp"
#include "output_files.hpp"

namespace hexatwist::cli {

/// A point log measured on the test (`hexatwist measure`), reported beside the simulation.
struct ReportedMeasurement {
  std::string source;                         ///< the point log's file
  Strategy strategy = Strategy::Compensated;  ///< the commands the platform ran
  std::string window;                         ///< how the registration window was chosen, for the reader
  Measurement measurement;
  std::vector<double> simulated;  ///< simulated error of the same strategy at each evaluated point [m]
  ErrorStats simulated_stats;     ///< statistics of `simulated` [m]
};

/// One simulated test with what is needed to report it.
struct ReportedTest {
  std::string name;         ///< file-name-safe: "Lz", or the trajectory file's stem
  std::string label;        ///< how messages name it: "Lz", or the trajectory file
  std::string description;  ///< "translation along z", or the trajectory file
  int coordinate = -1;      ///< swept pose coordinate 0..5; -1 = a user trajectory (plotted against time)
  double amplitude = 0.0;   ///< the sweep's amplitude [m or rad] (a study test)
  Trajectory trajectory;
  TestRun run;
  std::optional<ReportedMeasurement> measured;  ///< with `measure`: the experiment
  std::vector<EffectCost> effects;  ///< what the legs' effects cost on it (a configuration with leg_effects)
};

/// A study test to report: its name, label, description ("rotation about z, +-30 deg") and swept
/// coordinate (the trajectory is the caller's).
ReportedTest reported_test(const StudyTest& test);

/// A trajectory CSV file to report: read, parsed and resampled at `dt` [s] (ExitError(2) with the
/// parser's one-line message on a bad file), named after the file's stem (file-name safe); the
/// poses as in the file go to `commanded` if given.
ReportedTest reported_trajectory_file(const std::string& path, double dt, TimedPoses* commanded = nullptr);

/// Where and how to write.
struct ReportOptions {
  std::string out_dir;                           ///< created if missing
  std::string command;                           ///< "study", "simulate" or "measure", for the summary
  std::string config_source;                     ///< where the configuration came from
  std::string defaults;                          ///< defaults_note of the configuration
  bool figures = true;                           ///< draw PNG + SVG figures with gnuplot
  bool csv = true;                               ///< write the per-tick CSVs
  Vector6d temperature_rise = Vector6d::Zero();  ///< the legs' warm-up over each test, for the effects' costs [K]
};

/// Checks every test's trajectory against the limits first (ExitError(3) naming the test, time and
/// limit, and nothing runs, if one fails), then runs each test's three simulations (run_test), with a
/// progress bar on stderr when it is a terminal; then, on a configuration whose legs have effects,
/// what each costs on each test (effect_costs with `temperature_rise` [K]).
void simulate_tests(const Rig& rig, std::vector<ReportedTest>& tests, const Vector6d& temperature_rise);

/// What study, simulate and measure do once their tests are set up and `files` knows their inputs
/// and folder: simulate_tests, then `after_simulation` (may be empty; returns lines to print before
/// the table, e.g. the measurement's registration), then write_report, then files.finish() with
/// the text for the terminal: the platform, those lines, the table, the notes, and the time taken
/// since `start`. All or nothing: a failure at any step leaves the folder as it was.
void simulate_and_report(const Rig& rig, const ReportOptions& options, std::vector<ReportedTest>& tests,
                         OutputFiles& files, std::chrono::steady_clock::time_point start,
                         const std::function<std::string(std::vector<ReportedTest>&)>& after_simulation = {});

/// Notes for the reader that the table does not show (torque saturation); empty if none.
std::string report_notes(const Rig& rig, const std::vector<ReportedTest>& tests);

/// The Table 1-like table for the terminal [mm]: the simulation's rows, and an experiment row for
/// the tests with a measurement.
std::string summary_table(const std::vector<ReportedTest>& tests);

/// Adds summary.json, summary.md, the CSVs and (optionally) the figures in out_dir to `files` and
/// commits them (OutputFiles: on failure ExitError(kExitOutputFailed) names the file and the folder
/// is left as it was; an earlier run's files are moved aside). The summaries list the files written
/// besides themselves.
void write_report(const Rig& rig, const ReportOptions& options, const std::vector<ReportedTest>& tests,
                  OutputFiles& files);

}  // namespace hexatwist::cli
