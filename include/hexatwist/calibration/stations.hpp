// SPDX-License-Identifier: BSD-3-Clause
// The runs a calibration records: the calibration moves a measured test starts with (the paper's
// registration stations), and runs that stop at stations spread over the workspace for an
// identification (random ones here; planned ones in station_plan.hpp). Theory:
// docs/theory/calibration.md §12-13.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/motion/trajectory.hpp"
#include "hexatwist/simulation/study.hpp"

namespace hexatwist {

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
  /// Each station approached from both sides (identify's play): twice in a row, first from this
  /// far above it along z (every leg shortening to it: ds/dz = s_z > 0), then from as far below
  /// (every leg lengthening), the start poses rests too [m]; 0 = once, from the pose before. A side
  /// whose start pose, or a move to or from it, leaves a limit is left out (the station is
  /// then approached from one side or from the pose before). At most kMaxApproach.
  double approach = 0.0;
  /// Home again after every this many stations, a reference visited through the run (identify's
  /// heat: its repeats show the legs' drift apart from the geometry), where the moves to it and on
  /// to the next station stay inside the limits; 0 = only at the ends.
  int reference_every = 0;
};

/// The longest approach a stations run takes [m]: further, a leg's travel would be a station's.
inline constexpr double kMaxApproach = 0.05;

/// Most stations a run may have.
inline constexpr int kMaxStations = 10000;
/// The widest ranges stations are drawn in: +-10 m in x, y, z and +-90 deg in roll, pitch, yaw
/// (beyond, the pose's angles stop meaning what a person reads in them) [m, rad].
inline constexpr double kMaxStationTranslation = 10.0, kMaxStationRotation = 1.5707963267948966;

/// The one check of a StationsSpec, which random_stations, station_waypoints, the station plan,
/// the CLI and Python all go through: throws hexatwist::ParameterError naming the field out of its
/// range (count 1 to kMaxStations; translation 0 to kMaxStationTranslation and rotation 0 to
/// kMaxStationRotation, not both 0; approach 0 to kMaxApproach; reference_every >= 0; dwell and
/// the move limits finite and > 0).
void check_stations_spec(const StationsSpec& spec);

/// `spec.count` random stations, each drawn again (up to 1000 times) while it, or a pose every 5 mm
/// (or 5 mrad) along the straight move to it from the one before (home before the first), is
/// outside a limit of `model` for the commands of `strategy`; the last must also reach home. Poses
/// [m, rad] from home. Throws as check_stations_spec, and hexatwist::Error for no reachable
/// station in 1000 draws.
std::vector<Vector6d> random_stations(const Model& model, Strategy strategy, const StationsSpec& spec);

/// True if `to` and the poses every 5 mm (5 mrad) on the straight line from `from` to it are inside
/// every limit of `model` for the commands of `strategy` [m, rad].
bool reachable_from(const Model& model, Strategy strategy, const Vector6d& from, const Vector6d& to);

/// The poses a run visits, in order: home, the stations (each from both sides with spec.approach,
/// home again every spec.reference_every), home [m, rad]. Throws hexatwist::Error naming the
/// station if a move to it leaves a limit (reachable_from), and as check_stations_spec.
std::vector<Vector6d> station_waypoints(const Model& model, Strategy strategy, std::span<const Vector6d> stations,
                                        const StationsSpec& spec);

/// station_waypoints' poses with straight moves in pose coordinates between them (jerk-limited, as
/// waypoint_trajectory, with `spec.limits`), `spec.dwell` at each. Sampled every `dt` [s] from t0 =
/// 0. Throws as station_waypoints and waypoint_trajectory.
Trajectory station_run(const Model& model, Strategy strategy, std::span<const Vector6d> stations,
                       const StationsSpec& spec, double dt);

/// The run through random_stations(model, strategy, spec): station_run of them.
Trajectory stations_trajectory(const Model& model, Strategy strategy, const StationsSpec& spec, double dt);

}  // namespace hexatwist
