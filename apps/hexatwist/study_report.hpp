// What `hexatwist study` and `hexatwist simulate` write: the terminal table, summary.json,
// summary.md, one CSV per test and strategy, and the figures.
#pragma once

#include <string>
#include <vector>

#include "hexatwist/hexatwist.hpp"

namespace hexatwist::cli {

/// One simulated test with what is needed to report it.
struct ReportedTest {
  std::string name;         ///< file-name-safe: "Lz", or the trajectory file's stem
  std::string label;        ///< how messages name it: "Lz", or the trajectory file
  std::string description;  ///< "translation along z", or the trajectory file
  int coordinate = -1;      ///< swept pose coordinate 0..5; -1 = a user trajectory (plotted against time)
  Trajectory trajectory;
  TestRun run;
};

/// Where and how to write.
struct ReportOptions {
  std::string out_dir;        ///< created if missing
  std::string command;        ///< "study" or "simulate", for the summary
  std::string config_source;  ///< where the configuration came from
  bool figures = true;        ///< draw PNG + SVG figures with gnuplot
  bool csv = true;            ///< write the per-tick CSVs
};

/// Creates the output folder (if missing) and checks it is a folder; ExitError(4) otherwise.
/// Called before anything is simulated, so that a bad --out fails at once.
void prepare_output_folder(const std::string& out_dir);

/// Notes for the reader that the table does not show (torque saturation); empty if none.
std::string report_notes(const Rig& rig, const std::vector<ReportedTest>& tests);

/// The Table 1-like table for the terminal [mm].
std::string summary_table(const std::vector<ReportedTest>& tests);

/// Writes summary.json, summary.md, the CSVs and (optionally) the figures into out_dir; returns
/// the files written. Every file is written whole to a temporary name and renamed; on failure
/// throws ExitError(kExitOutputFailed) naming the file (files already complete stay).
std::vector<std::string> write_report(const Rig& rig, const ReportOptions& options,
                                      const std::vector<ReportedTest>& tests);

}  // namespace hexatwist::cli
