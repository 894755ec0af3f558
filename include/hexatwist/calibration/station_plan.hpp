// SPDX-License-Identifier: BSD-3-Clause
// Where to measure (issue 21): the stations of a calibration run chosen from a seeded set of
// candidate poses inside every limit so that the geometric model is best determined (the
// Ds-optimal criterion, by an exchange algorithm), ordered into a run of short moves that stay
// inside every limit, and their predicted accuracy beside that of random stations of the same
// count. Theory: docs/theory/calibration.md §13 ("Where to measure").
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hexatwist/calibration/identification.hpp"
#include "hexatwist/calibration/parameter_set.hpp"
#include "hexatwist/calibration/stations.hpp"

namespace hexatwist {

/// What to plan for. The stations' choice depends on the run, the ranges, the candidates and the
/// model only; the tracker's noise and points per station scale the covariance, not the choice.
struct StationPlanSpec {
  /// The run: its count, ranges (±translation [m], ±rotation [rad] from home in every coordinate),
  /// moves and dwell, and the seed of the candidates; random_stations(model, strategy, run) is the
  /// comparison.
  StationsSpec run;
  int candidates = 3000;                                ///< candidate poses drawn (seeded) inside every limit
  CalibrationModel model = CalibrationModel::Geometry;  ///< the parameters to determine
  LeadEffect lead_effect = LeadEffect::TwistAndTravel;  ///< as identify's
  AxisSelection axes{};                                 ///< U-joint axes to determine too (none by default)
  std::vector<Vector3d> targets_P;                      ///< targets beside the observation point [m, P] (at most 3)
  double noise = 10e-6;                                 ///< the tracker's noise per coordinate [m]
  int points_per_station = 75;      ///< points at rest per station (1 s at 100 Hz less identify's 0.25 s settle)
  int accuracy_poses = 1000;        ///< poses of the predicted accuracy over the range
  std::uint64_t accuracy_seed = 1;  ///< their seed
  int max_sweeps = 50;              ///< exchange sweeps at most
  /// An exchange is made when it raises the criterion by more than this (a determinant ratio of
  /// 1 + tolerance).
  double tolerance = 1e-6;
};

/// Most candidates a plan may draw.
inline constexpr int kMaxCandidates = 100000;

/// How well a run's stations determine the model.
struct StationsQuality {
  Status status = Status::NotIdentifiable;  ///< Ok, or why the stations do not determine the model (reason)
  std::string reason;                       ///< one line, for a status other than Ok
  std::vector<Vector6d> stations;           ///< in run order, home not included [m, rad from home]
  /// The Ds criterion: log det of the platform parameters' Fisher information with the tracker
  /// frame as nuisance (the Schur complement), home's two rests included [log of m^-2].
  double criterion = -std::numeric_limits<double>::infinity();
  /// The geometric mean of the parameters' standard deviations, det(C)^(1/2p) = exp(-criterion / 2p) [m].
  double sd_geometric = std::numeric_limits<double>::quiet_NaN();
  Eigen::MatrixXd covariance;   ///< of the platform parameters (ParameterSet order) [m^2]
  AccuracyPrediction accuracy;  ///< predicted point error over the spec's range from that covariance
  double path = 0.0;            ///< length of the moves home, stations, home in pose coordinates [m or rad]
  /// Condition number of the column-scaled measurement Jacobian, as identify computes it at the
  /// nominal model (theory §13); above 1e8 the stations do not determine the parameters.
  double condition = std::numeric_limits<double>::infinity();
};

/// Result of plan_stations (caller-owned).
struct StationPlan {
  Status status = Status::NotIdentifiable;  ///< Ok, or why not (reason)
  std::string reason;                       ///< one line, for a status other than Ok
  ParameterSet parameters;                  ///< the parameters planned for, in their order
  int candidates = 0;                       ///< candidates inside every limit and reachable from home
  int draws = 0;                            ///< poses drawn to find them
  int sweeps = 0;                           ///< exchange sweeps
  int exchanges = 0;                        ///< stations exchanged after the greedy start
  bool converged = false;                   ///< the last sweep made no exchange
  int replaced = 0;                         ///< stations replaced while ordering, their moves leaving a limit
  StationsQuality planned;                  ///< the plan
  /// random_stations of the same run spec; its own status says if they do not determine the model
  /// (the plan's status does not depend on it).
  StationsQuality random;
};

/// Throws hexatwist::ParameterError naming the field of `spec` that is out of its range (its
/// parameter(): count, translation, rotation, candidates, noise, points_per_station, accuracy_poses,
/// max_sweeps, tolerance, targets): count 1 to kMaxStations and enough to determine the
/// parameters, finite ranges >= 0, candidates count to kMaxCandidates, noise > 0, points per
/// station >= 1, accuracy poses >= 1, sweeps >= 0, tolerance >= 0, at most 3 more targets.
void check_station_plan_spec(const Model& nominal, const StationPlanSpec& spec);

/// Fewest stations whose rests (with home's) can determine every parameter of `spec`'s model.
int min_planned_stations(const Model& nominal, const StationPlanSpec& spec);

/// Plans a calibration run (theory §13): candidate poses drawn uniformly within the ranges (seeded)
/// that are inside every limit of `nominal` for the commands of `strategy` together with the
/// straight move from home; from them spec.run.count stations that maximise the Ds criterion, a
/// greedy start then the modified Fedorov exchange; ordered from home by nearest neighbour with
/// every straight move checked inside the limits (reachable_from; a station that cannot be reached
/// is exchanged for the best one that can); then the plan's quality beside that of random_stations
/// of spec.run. Returns Ok, NotIdentifiable (fewer reachable candidates than stations, an
/// information that stays singular, a station that cannot be reached), or a forward kinematics
/// status; out.reason says why. Throws as check_station_plan_spec.
[[nodiscard]] Status plan_stations(const Model& nominal, Strategy strategy, const StationPlanSpec& spec,
                                   StationPlan& out);

/// The quality of a run resting at home, at `stations` in order, and at home again, for `spec`'s
/// model, noise and points (as plan_stations reports it), its accuracy over spec.run's ranges.
/// Returns (and sets out.status to) Ok, NotIdentifiable (a column-scaled condition number above
/// 1e8, a station outside a limit) or a forward kinematics status; out.reason says why. Throws as
/// check_station_plan_spec.
[[nodiscard]] Status assess_stations(const Model& nominal, Strategy strategy, std::span<const Vector6d> stations,
                                     const StationPlanSpec& spec, StationsQuality& out);

}  // namespace hexatwist
