// SPDX-License-Identifier: BSD-3-Clause
// What an identification measures: tracker points of the platform's targets taken while the legs
// stood at known motor-side lengths, grouped by station (one commanded pose held) and target, and
// the tracker's own noise from their scatter at rest. Theory: docs/theory/calibration.md §13.
#pragma once

#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "hexatwist/calibration/point_log.hpp"
#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/motion/trajectory.hpp"

namespace hexatwist {

/// The largest tracker noise (a standard deviation per coordinate) a calibration takes: 10 mm [m].
inline constexpr double kMaxTrackerNoise = 0.01;
/// Most tracker points per station (and target) a plan or a simulated calibration takes.
inline constexpr int kMaxPointsPerStation = 100000;

/// One tracker measurement: where a target on the platform was seen while the legs stood at the
/// motor-side lengths they were commanded to.
struct Observation {
  Vector6d motor = Vector6d::Zero();  ///< commanded motor-side lengths m_k [m]
  Vector3d p_T = Vector3d::Zero();    ///< measured target [m, T]
  int target = 0;                     ///< which target (0: the observation point)
  /// When it was taken [s] (the trajectory's time): the time of the legs' drift (EffectFit::heat);
  /// NaN = unknown.
  double time = std::numeric_limits<double>::quiet_NaN();
  /// The machine's temperature when it was taken [degC] (the log's temperature column): heat then
  /// fits the legs' expansion per kelvin (EffectFit::measured); NaN = unknown.
  double temperature = std::numeric_limits<double>::quiet_NaN();
  /// Each leg's approach to the station (EffectFit::play): the length of the last monotone run of
  /// its commanded motor-side length before the station, positive lengthening, negative shortening
  /// [m]; a play longer than the run leaves the nut partway across its gap. 0 = unknown (then the
  /// stations' order gives the direction, the run taken as longer than any play).
  Vector6d approach = Vector6d::Zero();
};

/// The observations in groups: one station (a run of consecutive observations with the same
/// commands) and one target each. The least-squares cost of a group is that of its mean point
/// plus the scatter about it (theory §13), so the fit works on the means and the scatter measures
/// the tracker.
struct ObservationGroups {
  std::vector<int> group_of;       ///< per observation: its group
  std::vector<int> station;        ///< per group: its station (0-based, in the order of the log)
  std::vector<int> target;         ///< per group: its target
  std::vector<int> count;          ///< per group: its observations
  std::vector<std::size_t> first;  ///< per group: its first observation
  std::vector<Vector3d> mean_T;    ///< per group: the mean measured point [m, T]
  int stations = 0;                ///< stations (runs of one command)
  int targets = 0;                 ///< 1 + the largest target index
  double scatter_sum = 0.0;        ///< sum over observations of |p_T - mean_T|^2 [m^2]
  std::size_t scatter_dof = 0;     ///< 3 (observations - groups): the scatter's degrees of freedom
};

/// Two commands that differ by no more than this in every leg are one station [m].
inline constexpr double kSameCommand = 1e-9;

/// Groups the observations (see ObservationGroups). Stations are runs: a pose visited twice with
/// another in between is two stations.
ObservationGroups group_observations(std::span<const Observation> observations);

/// The tracker's noise per coordinate from the scatter of the points at rest about the mean of
/// their group, sqrt(scatter_sum / scatter_dof): it needs no model, so an identification's fit
/// noise is compared with it. NaN without repeated points [m].
double tracker_scatter(const ObservationGroups& groups) noexcept;

/// The points of a log that an identification can use, as observations.
struct ObservationSet {
  std::vector<Observation> observations;  ///< commanded motor-side lengths, the point as measured, its target
  std::vector<std::size_t> points;        ///< the log's index of each observation
  std::size_t poses = 0;                  ///< stations among them (runs of one commanded pose)
  double settle = 0.0;                    ///< the settle time applied [s]
  std::vector<std::string> targets;       ///< the targets' names (PointLog::target_names)
};

/// Fewest observations observations_at_rest accepts (an identification asks more, by its parameters).
inline constexpr std::size_t kMinObservations = 6;

/// The points of `log` taken while the commanded pose had been still for `settle` seconds (0 =
/// every point), each with the motor-side lengths that the nominal `model` commands for the
/// commanded pose under `strategy`: what the drives were told, which is where they stand once the
/// servo has settled, and each leg's approach: the last monotone run of its command along the
/// commanded trajectory before the station (followed back to 1 mm, the longest plausible play). Throws hexatwist::Error
/// with one line naming the log, and the line of a point at fault, for: a point outside the trajectory's time span, a
/// settle time that is not finite and >= 0, a commanded pose outside a limit, fewer than kMinObservations points at
/// rest.
ObservationSet observations_at_rest(const Model& model, const TimedPoses& commanded, const PointLog& log,
                                    const TimeAlignment& time, Strategy strategy, double settle);

}  // namespace hexatwist
