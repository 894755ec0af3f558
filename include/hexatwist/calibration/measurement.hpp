// Measured observation points, as in the paper's experiment (§5): a laser tracker's point log,
// its alignment in time with the commanded trajectory, the registration of the tracker frame T
// to the base frame B, and the observation-point errors that the study computes for the
// simulation, so that both can sit side by side (Table 1). Reading files is the caller's job.
// Theory: docs/theory.md §12.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "hexatwist/calibration/identification.hpp"
#include "hexatwist/calibration/registration.hpp"
#include "hexatwist/simulation/study.hpp"

namespace hexatwist {

// ---- the point log ----------------------------------------------------------------------------

/// How a point log names its columns and in which units. Tracker software exports differ
/// (SpatialAnalyzer-like `Time,X,Y,Z`, or `index,x_mm,y_mm,z_mm`).
struct PointLogFormat {
  /// Header names of the time (or sample index) column and of x, y, z. A header cell matches a
  /// name with case ignored, either as it is or followed by a unit suffix: `_s` or `_ms` for the
  /// time, `_m` or `_mm` for x, y, z (e.g. `x` matches `X`, `x_mm` and `X_MM`).
  std::string time_column = "t";
  std::string x_column = "x";
  std::string y_column = "y";
  std::string z_column = "z";
  /// Length unit of x, y, z for header names without a suffix [m per unit]: 1e-3 for mm, 1 for
  /// m; 0 = not given (then every coordinate column needs a suffix: "units missing" otherwise).
  /// A suffix that disagrees with a given unit is an error.
  double length_unit = 0.0;
  /// The time column holds a sample index (a whole number; no unit), not a time.
  bool indexed = false;
};

/// The points of a log, in the order of the file.
struct PointLog {
  std::vector<double> stamps;      ///< time [s], or sample index if `indexed`; strictly increasing
  std::vector<Vector3d> points_T;  ///< the observation point as measured [m, T]
  std::vector<int> lines;          ///< source line of each point (1-based)
  std::vector<int> stamp_columns;  ///< 1-based character column of each point's time cell
  std::string source;              ///< the log's name in messages (a file name)
  bool indexed = false;            ///< stamps are sample indices
};

/// Least number of points a log must hold: a rigid registration needs three.
inline constexpr std::size_t kMinLogPoints = 3;

/// Parses a point log: CSV with a header row, cells separated by commas without quoting, blank
/// and '#' lines skipped, CRLF and a UTF-8 byte-order mark accepted, other columns ignored but
/// every row with the header's number of cells. Values are returned in SI. Throws
/// hexatwist::Error with one line "source:line:column: column 'x': …" for: a column not in the
/// header (or named twice), units missing or contradictory, a row with another number of cells
/// than the header, an empty, non-numeric or non-finite cell, a sample index that is not a whole
/// number, stamps not strictly increasing, fewer than kMinLogPoints points, empty text.
PointLog parse_point_log(std::string_view text, std::string_view source, const PointLogFormat& format);

/// How the log's stamps map to the trajectory's time t (the time of the commanded trajectory).
struct TimeAlignment {
  double offset = 0.0;  ///< stamp time at which the trajectory's t = 0: t = stamp - offset [s]
  double rate = 0.0;    ///< for an indexed log, samples per second: t = index / rate - offset [Hz]
};

/// The trajectory time of each point [s]. Throws hexatwist::Error if the log is indexed and the
/// rate is not a finite number > 0, or the offset is not finite.
std::vector<double> trajectory_times(const PointLog& log, const TimeAlignment& alignment);

// ---- calibration moves ------------------------------------------------------------------------

/// The calibration moves a measured test starts with: the stations on which the tracker frame is
/// registered. The paper registers on "the home pose and the first calibration moves"; a sweep
/// alone cannot do it (the points of Lz and Lx lie on a line).
struct CalibrationSpec {
  double step = 0.2;                   ///< each station's translation from home along x, y and z [m]
  MotionLimits limits{0.2, 0.5, 2.5};  ///< the moves between stations [m/s, m/s^2, m/s^3] (the study's)
  double dwell = 1.0;                  ///< rest at each station [s]
};

/// A measured test: at rest at home, then translations to +step along x, y and z in turn and back
/// home (straight lines, jerk-limited, `dwell` at each station), then the study test, shifted to
/// start where the calibration ends. `calibration_end` receives that time [s]: the registration
/// window for the test. Sampled every `dt` [s] from t0 = 0. Throws as waypoint_trajectory.
Trajectory measured_test_trajectory(const StudySpec& study, const StudyTest& test, const CalibrationSpec& calibration,
                                    double dt, double& calibration_end);

/// A calibration run for identification (docs/theory.md §13): the platform stops at random poses
/// spread over the workspace, every coordinate at once, so that the tracker sees the lead, the
/// offsets and the observation point from many directions. The paper's tests alone leave some leg
/// offsets undetermined to ±0.1 mm; 40 stations with a 1 s rest fix them to a few µm.
struct StationsSpec {
  int count = 40;                      ///< stations, not counting home at the start and the end
  double translation = 0.25;           ///< each of x, y, z drawn uniformly in ±translation [m]
  double rotation = deg2rad(15.0);     ///< each of roll, pitch, yaw drawn uniformly in ±rotation [rad]
  MotionLimits limits{0.2, 0.5, 2.5};  ///< the moves, on the distance in pose coordinates [m or rad /s, /s^2, /s^3]
  double dwell = 1.0;                  ///< rest at each station [s]
  std::uint64_t seed = 1;              ///< the same seed gives the same stations everywhere
};

/// Home, then `spec.count` stations, then home: straight moves in pose coordinates (jerk-limited,
/// as waypoint_trajectory), `dwell` at each. A station is drawn again (up to 1000 times) while it,
/// or a pose every 5 mm (or 5 mrad) along the move to it, is outside a limit of `model` for the
/// commands of `strategy`. Sampled every `dt` [s] from t0 = 0. Throws hexatwist::Error for a count
/// below 1 or above 10000, a range that is not finite and >= 0, no reachable station in 1000
/// draws, and as waypoint_trajectory.
Trajectory stations_trajectory(const Model& model, Strategy strategy, const StationsSpec& spec, double dt);

// ---- registration and errors ------------------------------------------------------------------

/// Which points register the tracker frame: a leading part of the log (the window), and of it
/// the points where the platform stands still.
struct RegistrationWindow {
  /// The window: the points with t <= until [s] (when `first` is 0; NaN = not given) ...
  double until = std::numeric_limits<double>::quiet_NaN();
  /// ... or the first `first` points of the log (when > 0).
  std::size_t first = 0;
  /// Of the window, only points whose commanded pose has not changed for `settle` seconds
  /// (a trajectory's first pose counts as held since long before): the servo has settled
  /// there, so the model knows where the point is [s]. 0 = every point of the window.
  double settle = 0.25;
};

/// How to process a point log.
struct MeasurementOptions {
  TimeAlignment time;
  RegistrationWindow window;
  /// The commands the platform ran. A registration point's model position is the observation
  /// point where the nominal model puts it for these commands (twist-aware FK of the command of
  /// the commanded pose): the commanded position itself for the compensated commands, and with
  /// the twist's known error for the conventional ones, so that the registration does not absorb it.
  Strategy strategy = Strategy::Compensated;
  RegistrationOptions registration;
};

/// One measured point.
struct MeasuredPoint {
  double time = 0.0;                      ///< trajectory time [s]
  int line = 0;                           ///< source line
  Vector3d p_T = Vector3d::Zero();        ///< as measured [m, T]
  Vector3d p_B = Vector3d::Zero();        ///< registered: X_BT p_T [m, B]
  Vector6d desired = Vector6d::Zero();    ///< commanded pose [m, rad]
  Vector3d desired_B = Vector3d::Zero();  ///< the observation point at the commanded pose [m, B]
  Vector3d error_B = Vector3d::Zero();    ///< p_B - desired_B [m, B]
  bool in_window = false;                 ///< in the registration window
  bool registered = false;                ///< one of the registration's points (in the window, at rest)
  Vector3d model_B = Vector3d::Zero();    ///< for a registration point: its model position [m, B]
};

/// A processed point log.
struct Measurement {
  std::vector<MeasuredPoint> points;
  Registration registration;  ///< X_BT and its fit: residuals, noise estimate, condition
  /// The points that registered, in the order of the registration's pairs: points[registered[i]]
  /// is pair i (so the worst is points[registered[registration.max_residual_index]]).
  std::vector<std::size_t> registered;
  std::size_t window = 0;   ///< points in the registration window (points[0 .. window-1])
  double window_end = 0.0;  ///< trajectory time of the window's last point [s]
  /// The evaluated points are those after the window (the registration fits the window's
  /// points, so their errors are not measured but fitted): points[window ..].
  ErrorStats error;                ///< |error_B| over the evaluated points [m], as the study's
  std::array<ErrorStats, 3> axes;  ///< |x|, |y|, |z| of error_B over the evaluated points [m, B]
};

/// Aligns, registers and evaluates a point log against the commanded trajectory `commanded`
/// (poses at any times; interpolated as `interpolate` does). Throws hexatwist::Error with one
/// line naming the log (and its line and column where one point is at fault) for: a point
/// outside the trajectory's time span, a registration window with fewer than 3 points at rest or
/// with no point after it, a commanded pose in the window outside a limit or whose forward
/// kinematics fails, and a degenerate registration (collinear or coincident points).
Measurement measure_points(const Model& model, const TimedPoses& commanded, const PointLog& log,
                           const MeasurementOptions& options);

/// The simulated observation error (SimulationSample::error) at each evaluated point's time,
/// linearly interpolated between the control ticks (exact on a tick) [m]; NaN outside the ticks.
std::vector<double> simulated_errors(const std::vector<SimulationSample>& samples, const Measurement& measurement);

// ---- observations for identification ----------------------------------------------------------

/// The points of a log that an identification can use, as observations (identification.hpp).
struct ObservationSet {
  std::vector<Observation> observations;  ///< commanded motor-side lengths and the point as measured
  std::vector<std::size_t> points;        ///< the log's index of each observation
  std::size_t poses = 0;                  ///< distinct commanded poses among them (runs of one pose)
  double settle = 0.0;                    ///< the settle time applied [s]
};

/// The points of `log` taken while the commanded pose had been still for `settle` seconds (as the
/// registration's, RegistrationWindow::settle; 0 = every point), each with the motor-side lengths
/// that the nominal `model` commands for the commanded pose under `strategy`: what the drives were
/// told, which is where they stand once the servo has settled. Throws hexatwist::Error with one
/// line naming the log, and the line of a point at fault, for: a point outside the trajectory's
/// time span, a settle time that is not finite and >= 0, a commanded pose outside a limit, fewer
/// than 6 points at rest (16 parameters need 3K > 16).
ObservationSet observations_at_rest(const Model& model, const TimedPoses& commanded, const PointLog& log,
                                    const TimeAlignment& time, Strategy strategy, double settle);

}  // namespace hexatwist
