// SPDX-License-Identifier: BSD-3-Clause
// What synth, measure and identify share: the run the platform made (a study test after the
// calibration moves, a trajectory file or a stations run) and how to read a tracker's point log.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "cli_common.hpp"
#include "study_report.hpp"

namespace hexatwist::cli {

/// The run: one of --test, --trajectory, --stations; the strategy its commands were made with.
struct RunOptions {
  ModelOptions model;
  std::string test;
  std::string trajectory;
  int stations = 0;
  std::uint64_t station_seed = 1;
  double both_sides_mm = 0.0;  // StationsSpec::approach [mm]
  int reference_every = 0;     // StationsSpec::reference_every
  std::string strategy = "compensated";
};

/// The strategy named by --strategy.
Strategy strategy_of(const RunOptions& o);

/// The run to report, the commanded poses as given, and where the calibration moves end (NaN for a
/// trajectory file: its calibration is the user's).
struct Run {
  ReportedTest test;
  TimedPoses commanded;
  double calibration_end = std::numeric_limits<double>::quiet_NaN();
};

/// Builds the run the options name; ExitError(2) for a missing or unknown run, (3) for stations
/// that cannot be placed inside the limits.
Run build_run(const Config& config, const RunOptions& o);

/// Adds --config, --test, --trajectory, --stations, --station-seed, --both-sides-mm, --reference-every
/// and --strategy.
void add_run_options(CLI::App& app, RunOptions& o);

/// How to read a point log and place it in the run's time (measure and identify).
struct LogOptions {
  std::string points;
  std::string columns = "t,x,y,z";
  std::string units;
  bool index = false;
  double rate = 0.0;
  bool rate_given = false;         // --rate was given (0 is a value refused, not "none")
  std::string time_offset = "0";   // seconds, or "auto": from the rests (log_clock.hpp)
  std::string temperature_column;  // empty: a column named temperature or temperature_c, if any
};

/// Adds --points, --columns, --units, --index, --rate, --temperature-column and --time-offset.
void add_log_options(CLI::App& app, LogOptions& o);

/// The log's format from the options; ExitError(2) naming the option at fault.
PointLogFormat log_format(const LogOptions& o);

/// Reads and parses the log; ExitError(2) with the parser's one line.
PointLog read_point_log(const LogOptions& o, const PointLogFormat& format);

/// The log's clock against the run's: --time-offset SECONDS as given, or --time-offset auto found
/// from the rests (fit_log_clock; ExitError(2) with its reason when they do not match). `fit` gets
/// the fit (auto) or the given offset with scale 1 and nothing matched. With auto, the points
/// recorded before the run starts or after it ends are dropped from `log` (`dropped` counts them):
/// a tracker records whenever it was started.
TimeAlignment log_alignment(const LogOptions& o, const Run& run, PointLog& log, ClockFit& fit, std::size_t& dropped);

/// The clock's line of a report: "the log's clock: t_log = ... (from N rests ...)", or "" for a given offset.
std::string clock_line(const ClockFit& fit, const LogOptions& o, std::size_t dropped);

}  // namespace hexatwist::cli
