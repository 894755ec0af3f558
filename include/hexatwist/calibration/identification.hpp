// SPDX-License-Identifier: BSD-3-Clause
// Twist-aware calibration from a laser tracker's points (issues 5, 21): the U-joint centres, the
// screw leads, the sign of the twist term, each leg's zero offset, the targets on the platform and
// the tracker frame, by nonlinear least squares with standard deviations; and the decisions on
// the result, the same for every caller (CLI, C++, Python): is every parameter determined, is the
// thread hand decided, does the model explain the data as well as the tracker measures, how well
// does it predict stations left out, and how accurate will the corrected platform be. Theory:
// docs/theory/calibration.md §13.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hexatwist/calibration/observations.hpp"
#include "hexatwist/calibration/parameter_set.hpp"
#include "hexatwist/calibration/registration.hpp"
#include "hexatwist/kinematics/forward.hpp"

namespace hexatwist {

/// Which U-joint axes an identification fits (Geometry model).
enum class AxisFit {
  None,  ///< none: the axes as configured
  Auto,  ///< those the data determine to IdentificationOptions::axis_sd_max (theory §13)
  All,   ///< every axis
};

/// Settings of identify. The defaults are the CLI's and Python's, but for auto_effects: they choose
/// the effects (`--effects auto`, `effects="auto"`); a C++ caller asks for it.
struct IdentificationOptions {
  CalibrationModel model = CalibrationModel::Geometry;  ///< which parameters
  LeadEffect lead_effect = LeadEffect::TwistAndTravel;  ///< measurement model of the lead
  LeadFit leads = LeadFit::Shared;                      ///< one lead, or one per leg
  AxisFit axes = AxisFit::Auto;                         ///< which U-joint axes (Geometry)
  /// The legs' effects fitted besides the geometry (theory §13b): the load's deflection, the play
  /// and the legs' drift over the run (heat).
  EffectFit effects{};
  /// Choose the effects from the data instead (theory §13b): forward selection from none, adding
  /// the effect whose fit statistic drops most, while it drops by more than `effect_sigmas` normal
  /// deviates of its chi-square (the drop's degrees of freedom: the effect's parameters); an effect
  /// the data cannot carry (undetermined, or missing what it needs) is left out; none on the Basic
  /// model (its joints' errors would go into the effects). `effects` is ignored.
  bool auto_effects = false;
  double effect_sigmas = 5.0;
  /// Auto: an axis direction is fitted when the data determine both its angles to this [rad].
  double axis_sd_max = deg2rad(0.1);
  /// The tracker's noise per coordinate [m]; NaN = its scatter at rest (tracker_scatter), which
  /// needs several points per station and target.
  double tracker_noise = std::numeric_limits<double>::quiet_NaN();
  /// The tracker's noise counts as at least this (a log's rounding and the servo's settling are below it) [m].
  double tracker_noise_floor = 1e-6;
  /// The model-fit test: the fit's residual against the tracker's noise, refused beyond this many
  /// normal deviates of its F distribution (theory §13; 5 = a false alarm in 3.5 million fits).
  double fit_sigmas = 5.0;
  /// The thread hand: the rejected sign must fit worse by this many noise variances, 2 dC / sigma^2 (a
  /// chi-square of one degree of freedom: 25 = 5 sigma).
  double sign_separation_min = 25.0;
  int folds = 5;                    ///< cross-validation folds over the stations (0 = none; needs >= 2)
  int accuracy_poses = 1000;        ///< poses of the predicted accuracy over the calibrated range (0: none)
  std::uint64_t accuracy_seed = 1;  ///< their seed
  int max_iterations = 100;         ///< solver iterations per sign
  /// Largest accepted condition number of the column-scaled Jacobian; above it some parameter
  /// combination is undetermined (exact confounding gives about 1e15; at 1e6 the weakest
  /// combination's sd is already about a million times the best one's: 40 random stations give
  /// 5e3, 14 give 1e5).
  double max_condition = 1e6;
  /// A log whose start registration (the nominal model, the tracker frame by Kabsch) leaves an rms
  /// residual above this share of the model points' spread is not of this run: InvalidArgument,
  /// worded as measure_points words it (shape_misfit).
  double max_registration_misfit = kMaxRegistrationMisfit;
  FkOptions fk;  ///< forward kinematics of every station
};

/// The solve with the thread sense held at one value.
struct SignFit {
  double twist_sign = 0.0;                                ///< +1: every hand as configured, -1: all flipped
  Status status = Status::SolverNoConvergence;            ///< Ok, SolverNoConvergence or a forward kinematics status
  double cost = std::numeric_limits<double>::infinity();  ///< half the sum of squared residuals of all points [m^2]
  int iterations = 0;                                     ///< solver iterations
  bool lead_at_bound = false;                             ///< a lead ended at 0: this sense cannot explain the twist
  std::string message;                                    ///< the solver's account of why it stopped
  Eigen::VectorXd theta;  ///< where it stopped (ParameterSet order; the tracker rotation in X_BT)
  RigidTransform X_BT;    ///< the tracker frame there
};

/// A station with a large residual, for the report.
struct StationResidual {
  int station = -1;         ///< 0-based station (ObservationGroups::station)
  int target = 0;           ///< target
  std::size_t first = 0;    ///< its first observation
  int count = 0;            ///< its observations
  double mean_error = 0.0;  ///< |mean residual| [m]
  double statistic = 0.0;   ///< count |mean residual|^2 / sigma_tracker^2: its share of the fit test [-]
};

/// Stations left out and predicted (theory §13).
struct CrossValidation {
  int folds = 0;      ///< 0: not done
  int predicted = 0;  ///< groups predicted (each station and target once)
  /// rms of the predicted groups' mean residual, |mean point - prediction| [m], and what the
  /// tracker's noise and the parameters' covariance make it expected to be [m].
  double rms = std::numeric_limits<double>::quiet_NaN();
  double expected = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();  ///< largest predicted group's mean residual [m]
  Status status = Status::Ok;                             ///< a fold whose fit failed
};

/// The predicted accuracy of the corrected platform over the calibrated range (theory §13): at
/// random poses within the stations' range, inside every limit, the error of the target point
/// that the estimate's covariance predicts for compensated commands, sqrt(trace(G C G^T)) with
/// G = d A_B / d theta at fixed commands, in the gauge frames.
struct AccuracyPrediction {
  int poses = 0;                                             ///< poses evaluated
  double median = std::numeric_limits<double>::quiet_NaN();  ///< median predicted point error [m]
  double max = std::numeric_limits<double>::quiet_NaN();     ///< largest [m]
  /// The same after the best rigid re-alignment of the frames over these poses: the error the
  /// platform's shape leaves once a rigid motion (a registration) takes out the gauge frames' own
  /// uncertainty [m] (theory §13).
  double aligned_median = std::numeric_limits<double>::quiet_NaN();
  double aligned_max = std::numeric_limits<double>::quiet_NaN();
  Vector6d range_low = Vector6d::Zero();   ///< the calibrated range: the stations' smallest pose [m, rad]
  Vector6d range_high = Vector6d::Zero();  ///< and largest
};

/// Result of identify (caller-owned). The estimate, standard deviations and covariance are
/// meaningful when `fitted`; `corrected` when the status is Ok.
struct Identification {
  Status status = Status::NotIdentifiable;  ///< Ok, or why not (reason)
  std::string reason;                       ///< one line, for a status other than Ok
  std::string hint;                         ///< what to do about it (may be empty)
  bool fitted = false;                      ///< the solver ran to a usable solution
  ParameterSet parameters;                  ///< which parameters, in which order
  Eigen::VectorXd nominal;                  ///< the start: the nominal model's parameters
  Eigen::VectorXd estimate;                 ///< ParameterSet order [m; rad for the tracker rotation]
  Eigen::VectorXd sd;                       ///< standard deviations, the same order
  Eigen::MatrixXd covariance;               ///< sigma^2 (J^T J)^-1 in that order
  double twist_sign = 1.0;                  ///< +1: the thread hands as configured, -1: all flipped
  RigidTransform X_BT;                      ///< the tracker frame in the base frame
  ModelSpec corrected;                      ///< the corrected platform (ParameterSet::platform of the estimate)
  /// The joint centres' estimated displacement from the nominal ones and its standard deviation,
  /// per leg: base [m, B], platform [m, P] (zero in the Basic model).
  LegVectors base_shift = LegVectors::Zero(), base_shift_sd = LegVectors::Zero();
  LegVectors platform_shift = LegVectors::Zero(), platform_shift_sd = LegVectors::Zero();
  /// The axes' predicted standard deviations if all were fitted (both angles, the larger) [rad]:
  /// legs 1..6 base, then platform; NaN where not computed. Which were fitted: parameters.axes().
  std::array<double, 2 * kLegs> axis_sd;
  int observations = 0;  ///< points used
  int stations = 0;      ///< stations (runs of one command)
  int groups = 0;        ///< stations times the targets they measured
  double sigma =
      std::numeric_limits<double>::quiet_NaN();  ///< the fit's noise per coordinate, sqrt(sum |e|^2 / (3K - p)) [m]
  /// The tracker's noise per coordinate the test uses [m]: options.tracker_noise or the scatter at
  /// rest, at least the floor.
  double tracker_noise = std::numeric_limits<double>::quiet_NaN();
  double scatter = std::numeric_limits<double>::quiet_NaN();  ///< the scatter at rest [m] (NaN without repeats)
  /// The model-fit test (theory §13): T = sum_groups count |mean residual|^2 / tracker_noise^2 on
  /// dof = 3 groups - p degrees of freedom, and its normal deviate z (Paulson's approximation of
  /// the F distribution; the model fails the test above options.fit_sigmas).
  double fit_statistic = std::numeric_limits<double>::quiet_NaN();
  int fit_dof = 0;
  double fit_z = std::numeric_limits<double>::quiet_NaN();
  /// What the model leaves beyond the tracker's noise, per point and coordinate [m]: the fit
  /// statistic's excess over its expectation, sqrt(max(0, sum_g count_g |mean residual_g|^2 - dof
  /// tracker_noise^2) / (3 points)) (0 when the fit is within the noise).
  double unexplained = std::numeric_limits<double>::quiet_NaN();
  /// On ModelMismatch with the geometry model: each effect not fitted, tried alone on top of those
  /// fitted, with its drop of the fit statistic in sigma (NaN where it cannot be fitted); those
  /// above options.effect_sigmas are what the residuals point to (the hint names them).
  struct EffectDiagnosis {
    std::string effect;  ///< "load", "play" or "heat"
    double z = std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<EffectDiagnosis> diagnosis;
  std::vector<StationResidual> worst;  ///< the stations with the largest shares of T, largest first (up to 5)
  double rms_before =
      std::numeric_limits<double>::quiet_NaN();  ///< rms 3-D residual of the nominal model after Kabsch [m]
  double rms_after = std::numeric_limits<double>::quiet_NaN();  ///< rms 3-D residual at the estimate [m]
  double max_after = std::numeric_limits<double>::quiet_NaN();  ///< largest 3-D residual at the estimate [m]
  int max_after_index = -1;                                     ///< 0-based observation with the largest
  std::vector<Vector3d> residual_B;  ///< per observation, X_BT p_T minus the model's target [m, B]
  std::array<SignFit, 2> fits;       ///< the solves with sign +1 ([0]) and -1 ([1])
  double cost_ratio = std::numeric_limits<double>::quiet_NaN();       ///< rejected sign's cost over the chosen one's
  double sign_separation = std::numeric_limits<double>::quiet_NaN();  ///< 2 (C_rejected - C_chosen) / sigma^2
  /// Condition number of the column-scaled Jacobian at the estimate (at the start if it failed there).
  double condition = std::numeric_limits<double>::infinity();
  Eigen::VectorXd weakest;   ///< least-determined unit combination of column-scaled parameters
  std::string undetermined;  ///< the parameters that enter the undetermined combinations
  CrossValidation cross_validation;
  AccuracyPrediction accuracy;
  /// With IdentificationOptions::auto_effects: how the effects were chosen, one line ("" otherwise).
  std::string effects_choice;

  Identification() { axis_sd.fill(std::numeric_limits<double>::quiet_NaN()); }
};

/// Most cross-validation folds.
inline constexpr int kMaxFolds = 100;

/// The one check of IdentificationOptions (identify runs it; the CLI and Python reach it through
/// identify): throws hexatwist::ParameterError naming the field out of its range. tracker_noise NaN
/// or in (0, kMaxTrackerNoise); tracker_noise_floor in [0, kMaxTrackerNoise); fit_sigmas,
/// effect_sigmas, sign_separation_min, axis_sd_max and max_registration_misfit finite and > 0;
/// folds 0 (none) or 2 to kMaxFolds; accuracy_poses 0 (none) to 100000; max_iterations >= 1;
/// max_condition finite and > 1; fk as check_fk_options.
void check_identification_options(const IdentificationOptions& options);

/// Identifies the platform from the observations (theory §13): the nominal model and a Kabsch
/// start, both thread senses by Levenberg-Marquardt (Ceres), the sense of lower cost; with
/// AxisFit::Auto the axes the data determine; then the decisions. Returns Ok, or: NonFiniteInput;
/// NotIdentifiable (too few observations or stations, a failed start registration, a
/// rank-deficient Jacobian naming the parameters, a leg without U-joint axes, an unknown tracker
/// noise); SignUndecided (both senses fit alike); ModelMismatch (the fit leaves more than the
/// tracker's noise: the worst stations and a hint are given); SolverNoConvergence; or a forward
/// kinematics status. `out.reason` says why in one line; `out.hint` what to do. Throws as
/// check_identification_options for options out of their ranges.
[[nodiscard]] Status identify(const Model& nominal, std::span<const Observation> observations, Identification& out,
                              const IdentificationOptions& options = {});

/// The residual of every observation, X_BT p_T - A_B [m, B] (3K, observation k at rows 3k..3k+2),
/// of the platform theta with thread sense `sign` and tracker frame X_BT, and optionally their
/// Jacobian (3K x set.size(), the rotation as the left perturbation dw). Returns Ok or the status
/// of the candidate model or of a forward kinematics.
[[nodiscard]] Status identification_residuals(const ParameterSet& set, std::span<const Observation> observations,
                                              const Eigen::VectorXd& theta, double sign, const RigidTransform& X_BT,
                                              const FkOptions& fk, Eigen::VectorXd& residuals, Eigen::MatrixXd* J);

/// The prediction of AccuracyPrediction for a covariance `covariance` of the platform parameters
/// (set.platform_size() square) at `theta`, `sign`, over `poses` poses drawn within [low, high]
/// (seeded) inside every limit of the platform; the errors at each pose are written to `errors` if
/// given [m]. Returns Ok, NotIdentifiable (no pose of the range inside the limits) or a forward
/// kinematics status.
[[nodiscard]] Status predicted_accuracy(const ParameterSet& set, const Eigen::VectorXd& theta, double sign,
                                        const Eigen::MatrixXd& covariance, const Vector6d& low, const Vector6d& high,
                                        int poses, std::uint64_t seed, AccuracyPrediction& out,
                                        std::vector<Vector6d>* poses_out = nullptr,
                                        std::vector<double>* errors = nullptr);

/// The predicted point error [m] at each pose of `poses` (m, rad from home; NaN outside a limit),
/// as AccuracyPrediction: for the map figure and for Python.
[[nodiscard]] Status predicted_errors(const ParameterSet& set, const Eigen::VectorXd& theta, double sign,
                                      const Eigen::MatrixXd& covariance, std::span<const Vector6d> poses,
                                      std::vector<double>& errors);

/// The predicted point error over a slice of the calibrated range (a map figure): positions on a
/// grid in the plane of two coordinates, the third at the range's middle, the orientation zero.
struct AccuracyMap {
  int axis_u = 0, axis_v = 1;  ///< the plane's coordinates (0, 1, 2 = x, y, z)
  std::vector<double> u, v;    ///< the grid's coordinates along them [m]
  /// Predicted point error at (u[i], v[j]) in error[j * u.size() + i] [m]; NaN outside a limit.
  std::vector<double> error;
};

/// The map of `range` in the plane of coordinates axis_u, axis_v with n x n positions (n >= 2), as
/// predicted_errors. Returns its status.
[[nodiscard]] Status accuracy_map(const ParameterSet& set, const Eigen::VectorXd& theta, double sign,
                                  const Eigen::MatrixXd& covariance, const AccuracyPrediction& range, int axis_u,
                                  int axis_v, int n, AccuracyMap& out);

}  // namespace hexatwist
