// SPDX-License-Identifier: BSD-3-Clause
// The calibration a tolerance study simulates (docs/theory/design.md §18): what a laser tracker
// records of each sampled platform at the stations of a plan, the twist-aware identification of
// those points (calibration/identification.hpp) and the configuration its controller runs
// afterwards; and the linearised answer, the point error that the identification's covariance
// predicts over the workspace, to check the Monte Carlo against.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "hexatwist/calibration/identification.hpp"
#include "hexatwist/calibration/point_log.hpp"
#include "hexatwist/calibration/stations.hpp"
#include "hexatwist/design/tolerance.hpp"
#include "hexatwist/motion/trajectory.hpp"

namespace hexatwist {

/// The identification a study runs on every sampled platform: the Geometry model (joint centres,
/// leads, offsets, target, the axes the data determine), no cross-validation and no predicted
/// accuracy (the study measures the accuracy itself); the tracker's noise from the points' scatter.
IdentificationOptions study_identification_options();

/// The frames a calibrated platform's errors are measured in (CalibratedController).
enum class CalibratedFrames {
  /// The base as the tracker sees it through the identified tracker frame, the platform frame that
  /// of the real platform's joints: what the tracker measures when it checks the calibrated machine
  Tracker,
  /// The least-squares frames of the real base and platform joints, the identification's gauge
  /// (theory §13): what predicted_errors predicts, with the joints' weakly determined placement
  Joints,
};

/// A simulated tracker calibration: the plan, the tracker, the identification.
struct TrackerCalibration {
  /// The plan: the poses the platform stops at, in order [m, rad from home]; each commanded by the
  /// nominal model's compensated commands (random_stations, or a planner's).
  std::vector<Vector6d> stations;
  double noise = 10e-6;  ///< the tracker's Gaussian noise per coordinate [m]
  int points = 50;       ///< points recorded per station (at rest), of each target
  /// More targets on the platform, each measured at every station beside the observation point
  /// (target 0) [m, P]: the identification places them (their positions are parameters), and with
  /// them the platform's orientation, so that the pivot and the orientation calibrate as point A does.
  std::vector<Vector3d> extra_targets_P;
  std::uint64_t seed = 1;  ///< with a sample's index, the tracker's placement and noise
  IdentificationOptions identification = study_identification_options();
  CalibratedFrames frames = CalibratedFrames::Tracker;  ///< where the errors are measured
};

/// Throws hexatwist::ParameterError naming the field when `calibration` is unusable: no station, a station
/// that is not finite, a noise outside (0, kMaxTrackerNoise), points outside 1..kMaxPointsPerStation,
/// a single point per station without identification.tracker_noise (the scatter needs two), an
/// identification of another model than Geometry (the study's errors move the joints), more than
/// kMaxTargets targets with the observation point, or one that is not finite, farther than 10 m from
/// the platform frame's origin, or within 1 mm of another.
void check_tracker_calibration(const TrackerCalibration& calibration);

/// The plan of `count` random stations (random_stations, compensated commands) between home at the
/// start and home at the end, as a stations run records them (station_run). Throws as random_stations.
std::vector<Vector6d> random_station_plan(const Model& nominal, const StationsSpec& spec);

/// The stations of a run (a stations run's commanded poses, as synth --run-out writes them): every
/// pose the run holds for two or more consecutive samples, once per hold, in order [m, rad from home].
std::vector<Vector6d> run_stations(const TimedPoses& run);

/// The tracker's placement X_BT for sample `index` (random_tracker_frame, seeded by (calibration.seed, index)).
RigidTransform sample_tracker_frame(const TrackerCalibration& calibration, std::uint64_t index);

/// The least-squares (Kabsch) placements of the nominal joints onto the real ones: the frames of
/// `real`'s base joints in B (X_BJ) and of its platform joints in P (X_PJ). They meet exactly the
/// gauge conditions of an identification's joints (theory §13).
[[nodiscard]] Status joint_frames(const Model& nominal, const Model& real, RigidTransform& X_BJ, RigidTransform& X_PJ);

/// The tracker's noise of sample `index`, every point of every target of every station in order
/// [m, T] (what tracker_observations adds).
std::vector<Vector3d> tracker_noise(const TrackerCalibration& calibration, std::uint64_t index);

/// What the tracker records of the platform `real` (the nominal model's sample `index` of a study)
/// at every station: the nominal model's compensated commands held, the pose they give `real`
/// (motor-side forward kinematics: its joints, leads, offsets, the drives' reference and scale),
/// there its observation point and then each extra target (Observation::target 1, 2, ...), in a
/// tracker frame drawn for the sample (random_tracker_frame), `points` times each with independent
/// Gaussian noise. Depends on (calibration.seed, index) alone.
/// Returns Ok, the status of a station the nominal model refuses, or of the forward kinematics.
[[nodiscard]] Status tracker_observations(const Model& nominal, const Model& real,
                                          const TrackerCalibration& calibration, std::uint64_t index,
                                          std::vector<Observation>& out);

/// The calibration of sample `index`: tracker_observations, then identify with
/// calibration.identification. Returns the identification's status (or the observations').
[[nodiscard]] Status calibrate_sample(const Model& nominal, const Model& real, const TrackerCalibration& calibration,
                                      std::uint64_t index, Identification& out);

/// The study's calibration step: calibrate_sample, the controller running the identification's
/// corrected configuration, in calibration.frames: X_PC the real platform joints' frame; X_CB the
/// real base seen by the tracker and mapped back by the identified tracker frame (Tracker) or the
/// real base joints' frame (Joints). Throws as check_tracker_calibration.
CalibrationStep tracker_calibration_step(const TrackerCalibration& calibration);

/// The linearised answer after a calibration, at the nominal platform (theory design §18). The
/// identification's covariance C = noise^2 (J^T J)^-1 (J its Jacobian of the plan's stations, each
/// weighted by its points; the axes chosen as identify's AxisFit would) and the bias the axes it
/// leaves put into its estimate, (J^T J)^-1 J^T J_u u for their manufacturing errors u,
/// propagated to each pose: the errors of point A, the pivot and the orientation for compensated
/// commands. In the Joints frames through d(where the commands put them)/d(platform parameters),
/// the tracker frame a nuisance (as predicted_errors); in the Tracker frames through the
/// identification's residual row at the pose, the tracker frame included (theory §13).
struct CalibratedLinear {
  ParameterSet parameters;          ///< the parameters identified, in their order
  Eigen::MatrixXd jacobian;         ///< J, 3 per station (weighted by its points) x parameters
  Eigen::MatrixXd covariance;       ///< C, the platform parameters then the tracker frame [m, rad]^2
  double condition = 0.0;           ///< column-scaled condition number of J
  std::vector<double> point_error;  ///< per pose, sqrt(trace G C G^T) of the noise alone, as predicted_errors [m]
};

/// The linearised answer of `calibration` for the study `study` (its sigmas, seed and threads)
/// over `poses` into `out`: the covariances; point_factor, the pose's point error per unit of the
/// coordinates z = (the noise response L^-1 dtheta, the left axes' errors over their standard
/// deviations); and draw, a sample's z from its own tracker noise (regenerated from (seed, index)
/// as tracker_observations draws it) and axes, the linear model with the same errors. `point`
/// stays empty. Returns Ok, NotIdentifiable (the plan does not determine the parameters), or the
/// status of a pose or station the nominal model refuses. Throws as check_tracker_calibration.
[[nodiscard]] Status calibrated_linear(const Model& nominal, const std::vector<Pose>& poses,
                                       const ToleranceOptions& study, const TrackerCalibration& calibration,
                                       ToleranceLinear& out, CalibratedLinear* detail = nullptr);

/// Most extra targets target_layouts compares.
inline constexpr int kMaxLayoutTargets = 5;

/// The `extra` targets of a layout besides point A (theory design §18, "Where to put the targets"):
/// with point A evenly spaced on the circle through A about the platform's z axis through the pivot,
/// in A's plane; its radius that of A, or the platform joints' mean radius when A is within 0.1 m of
/// the axis (then A's place on it is +x). [m, P]
std::vector<Vector3d> target_layout(const Model& nominal, int extra);

/// What a layout of targets buys: the calibration with it, linearised (calibrated_linear), its
/// quantiles (linear_quantiles: median and 95th percentile over the poses).
struct TargetLayout {
  std::vector<Vector3d> extra_targets_P;  ///< besides point A [m, P]
  Status status = Status::Ok;             ///< calibrated_linear's (NotIdentifiable: the plan does not determine it)
  ErrorQuantiles point, position, orientation;  ///< point A, the pivot [m], the orientation [rad]
};

/// The layouts of 0 to `max_extra` extra targets (target_layout) for `calibration` (its plan, tracker
/// and frames; its own targets replaced), each answered by the linear model over `poses` with
/// `study`'s sigmas, seed and threads. Throws ParameterError for max_extra outside 0..kMaxLayoutTargets
/// and as check_tracker_calibration.
std::vector<TargetLayout> target_layouts(const Model& nominal, const std::vector<Pose>& poses,
                                         const ToleranceOptions& study, const TrackerCalibration& calibration,
                                         int max_extra);

/// A study's calibration as the command line and Python name it.
struct CalibrationChoice {
  /// none (the nominal controller), perfect (perfect_calibration_step), stations:N[,SEED]
  /// (random_station_plan of N stations, their seed SEED, 1 by default) or plan (`plan` below)
  std::string name = "none";
  std::vector<Vector6d> plan;    ///< for "plan": the stations [m, rad from home]
  double tracker_noise = 10e-6;  ///< the tracker's noise per coordinate [m]
  int points = 50;  ///< points per station; one: the identification is given the tracker's noise (no scatter)
  CalibratedFrames frames = CalibratedFrames::Tracker;
  std::vector<Vector3d> extra_targets_P;  ///< TrackerCalibration::extra_targets_P [m, P]
};

/// The tracker calibration that prepare_calibration makes of `choice` (empty stations for none and
/// perfect). Throws as prepare_calibration.
TrackerCalibration tracker_calibration_of(const Model& nominal, const CalibrationChoice& choice, std::uint64_t seed);

/// Whether the calibration `name` is a tracker's (stations:N[,SEED] or plan: each platform identified
/// from simulated tracker points, its errors small enough to report in um), as prepare_calibration reads it.
bool is_tracker_calibration(std::string_view name) noexcept;

/// Prepares a study for `choice`: options.calibration (empty for none), and the linear model for
/// its summary and max_point_linear: tolerance_linear, or after a tracker calibration (seeded with
/// options.seed) calibrated_linear. Throws hexatwist::ParameterError ("calibration", "station_plan")
/// starting "calibration: " for a name it does not know, plan without stations, a station count
/// outside 1..kMaxStations, and as check_tracker_calibration and random_stations. Returns the linear model's status.
[[nodiscard]] Status prepare_calibration(const Model& nominal, const std::vector<Pose>& poses,
                                         const CalibrationChoice& choice, ToleranceOptions& options,
                                         ToleranceLinear& linear);

}  // namespace hexatwist
