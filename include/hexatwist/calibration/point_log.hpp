// SPDX-License-Identifier: BSD-3-Clause
// A laser tracker's point log: the points of one or more targets on the platform with their time
// stamps, as tracker software exports them (CSV), and their alignment with a commanded run's time.
// Reading files is the caller's job. Theory: docs/theory/calibration.md §12.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "hexatwist/types.hpp"

namespace hexatwist {

/// How a point log names its columns and in which units. Tracker software exports differ
/// (SpatialAnalyzer-like `Time,X,Y,Z`, or `index,x_mm,y_mm,z_mm`).
struct PointLogFormat {
  /// Header names of the time (or sample index) column and of x, y, z. A header cell matches a
  /// name with case ignored, either as it is or followed by a unit suffix: `_s` or `_ms` for the
  /// time, `_m` or `_mm` for x, y, z (e.g. `x` matches `X`, `x_mm` and `X_MM`). A name that carries
  /// a suffix itself (`x_mm`) gives the unit by it.
  std::string time_column = "t";
  std::string x_column = "x";
  std::string y_column = "y";
  std::string z_column = "z";
  /// Header name of the column that says which target on the platform a row measured (a name or
  /// a number per row, case kept); empty = no such column unless the header has one named
  /// `target` (case ignored): then every row is the one target, the observation point.
  std::string target_column;
  /// Header name of the machine's temperature column [degC] (a `_c` suffix allowed); empty = none
  /// unless the header has one named `temperature` or `temperature_c` (case ignored).
  std::string temperature_column;
  /// Length unit of x, y, z for header names without a suffix [m per unit]: 1e-3 for mm, 1 for
  /// m; 0 = not given (then every coordinate column needs a suffix: "units missing" otherwise).
  /// A suffix that disagrees with a given unit is an error.
  double length_unit = 0.0;
  /// The time column holds a sample index (a whole number; no unit), not a time.
  bool indexed = false;
};

/// The points of a log, in the order of the file.
struct PointLog {
  std::vector<double> stamps;             ///< time [s], or sample index if `indexed`; increasing per target
  std::vector<Vector3d> points_T;         ///< the target as measured [m, T]
  std::vector<int> targets;               ///< which target each point is of: an index into `target_names`
  std::vector<std::string> target_names;  ///< in order of first appearance; target 0 is the observation point
  std::vector<double> temperatures;       ///< the machine's temperature at each point [degC]; empty = no column
  std::vector<int> lines;                 ///< source line of each point (1-based)
  std::vector<int> stamp_columns;         ///< 1-based character column of each point's time cell
  std::string source;                     ///< the log's name in messages (a file name)
  bool indexed = false;                   ///< stamps are sample indices
};

/// Least number of points a log must hold: a rigid registration needs three.
inline constexpr std::size_t kMinLogPoints = 3;
/// Most targets a log may carry.
inline constexpr std::size_t kMaxTargets = 16;
/// The range of a log's temperatures a machine works in [degC]; outside, a sensor or unit error.
inline constexpr double kMinLogTemperature = -40.0;
inline constexpr double kMaxLogTemperature = 150.0;

/// Parses a point log: CSV with a header row, cells separated by commas without quoting, blank
/// and '#' lines skipped, CRLF and a UTF-8 byte-order mark accepted, other columns ignored but
/// every row with the header's number of cells. Values are returned in SI. With a target column
/// (PointLogFormat::target_column), each row names its target and the stamps increase per target
/// (the targets of one instant may share a stamp). Throws hexatwist::Error with one line
/// "source:line:column: column 'x': …" for: a column not in the header (or named twice), units
/// missing or contradictory, a row with another number of cells than the header, an empty,
/// non-numeric or non-finite cell, an empty target name or more than kMaxTargets targets, a sample
/// index that is not a whole number, stamps not strictly increasing (per target), fewer than
/// kMinLogPoints points, empty text.
PointLog parse_point_log(std::string_view text, std::string_view source, const PointLogFormat& format);

/// How the log's stamps map to the trajectory's time t (the time of the commanded trajectory).
struct TimeAlignment {
  double offset = 0.0;  ///< stamp time at which the trajectory's t = 0: t = (stamp - offset) / scale [s]
  double rate = 0.0;    ///< for an indexed log, samples per second: stamp time = index / rate [Hz]
  /// The log's seconds per second of the run (1 + the clocks' rate difference; log_clock.hpp finds
  /// it with the offset); 1 for clocks that agree.
  double scale = 1.0;
};

/// The trajectory time of each point [s]. Throws hexatwist::Error if the log is indexed and the
/// rate is not a finite number > 0, the offset is not finite, or the scale not finite and > 0.
std::vector<double> trajectory_times(const PointLog& log, const TimeAlignment& alignment);

}  // namespace hexatwist
