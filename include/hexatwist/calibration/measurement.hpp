// SPDX-License-Identifier: BSD-3-Clause
// Measured observation points, as in the paper's experiment (§5): a point log aligned in time with
// the commanded trajectory, the registration of the tracker frame T to the base frame B, and the
// observation-point errors that the study computes for the simulation, so that both can sit side by
// side (Table 1). Theory: docs/theory/calibration.md §12.
#pragma once

#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "hexatwist/calibration/point_log.hpp"
#include "hexatwist/calibration/registration.hpp"
#include "hexatwist/calibration/stations.hpp"
#include "hexatwist/simulation/study.hpp"

namespace hexatwist {

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
  /// A log whose registration leaves an rms residual above this fraction of the registration
  /// points' rms spread does not have the run's shape (a log in metres labelled _mm, another
  /// run's log): refused. A platform that is millimetres off its drawing leaves well under 5 %
  /// over calibration moves that span decimetres.
  double max_registration_misfit = kMaxRegistrationMisfit;
  /// A log whose evaluated errors have an rms above both this fraction of the observation point's
  /// commanded motion (rms about its mean over the evaluated points) and `max_error_floor` is of
  /// another motion than the run's (the log of one test measured as another): refused.
  double max_error_fraction = 0.25;
  double max_error_floor = 0.01;  ///< [m]
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
/// kinematics fails, a degenerate registration (collinear or coincident points), and a log that
/// is not of this run: a registration misfit above `max_registration_misfit`, a point farther from
/// where the run puts it than the legs' maximum length, or evaluated errors above
/// `max_error_fraction` of the motion (and `max_error_floor`). Errors blamed on an option are
/// ParameterError (time_offset, register_until, register_first, settle).
Measurement measure_points(const Model& model, const TimedPoses& commanded, const PointLog& log,
                           const MeasurementOptions& options);

/// The simulated observation error (SimulationSample::error) at each evaluated point's time,
/// linearly interpolated between the control ticks (exact on a tick) [m]; NaN outside the ticks.
std::vector<double> simulated_errors(const std::vector<SimulationSample>& samples, const Measurement& measurement);

}  // namespace hexatwist
