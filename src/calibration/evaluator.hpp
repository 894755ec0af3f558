// SPDX-License-Identifier: BSD-3-Clause
// Internal: the measurement model of an identification (docs/theory/calibration.md §13): the pose
// each station's commands put the candidate platform in, the residuals of the groups' mean points,
// and their exact Jacobian by the implicit function theorem through twist-aware forward kinematics,
// with the twist's dependence on the joints and axes.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hexatwist/calibration/observations.hpp"
#include "hexatwist/calibration/parameter_set.hpp"
#include "hexatwist/calibration/registration.hpp"
#include "hexatwist/kinematics/forward.hpp"

namespace hexatwist::detail {

/// How the pose that a command puts the platform in moves with the platform parameters.
struct StationSensitivity {
  FkResult fk;                                         ///< the pose reached
  Eigen::Matrix<double, 6, Eigen::Dynamic> dx_dtheta;  ///< d[t; w]/d theta_platform (6 x platform_size)
};

/// d x / d theta (6 x set.platform_size()) at the solution `fk` of `candidate` (the platform
/// set.platform(theta, sign)) for the drives' commands `motor`: -J_f_x^-1 df/dtheta with
/// f = |L| - offset - k dtheta(x) - travel(m) (theory §13). Returns a forward-kinematics status.
/// `effects` (may be null): the station's regressors of the legs' effects (6 x set.effects().count(),
/// EffectRegressors), whose length shift enters f as the offsets do.
Status pose_sensitivity(const Model& candidate, const ParameterSet& set, const FkResult& fk, const Vector6d& motor,
                        Eigen::Matrix<double, 6, Eigen::Dynamic>& dx_dtheta,
                        const Eigen::Matrix<double, 6, Eigen::Dynamic>* effects = nullptr);

/// The legs' effects at each station (theory §13b): each leg's approach (Observation::approach; from
/// the stations' order where unknown, starting from home in the homing direction), and the
/// regressors whose product with the effects' parameters (ParameterSet::effect_index() on), plus
/// `constant`, is each leg's length shift [m]. The play's columns and constant depend on the plays
/// themselves (a play longer than the approach leaves the nut partway): play_terms sets them.
struct EffectRegressors {
  Status status = Status::Ok;  ///< NotIdentifiable where an effect cannot be modelled (reason says why)
  std::string reason;
  std::vector<Vector6d> approach;                                    ///< per station, signed run [m]
  std::vector<Eigen::Matrix<double, 6, Eigen::Dynamic>> regressors;  ///< per station, 6 x count
  std::vector<Vector6d> constant;                                    ///< per station [m]
};

/// The least spread of a log's temperatures over the run that heat's expansions are fitted from [K].
inline constexpr double kMinTemperatureSpread = 0.1;

/// Each leg's play term at a station with approach `approach` [m] (signed run) for the plays `play`
/// [m]: E = -(b/2)(d - d_home) with the nut's direction d = sign(run) where b <= |run|, and
/// sign(run)(2|run|/b - 1) where the run ends inside the gap (the nut dragged from the far side):
/// E = coefficient b + constant in either case, written to `coefficient` and `constant`; `direction`
/// receives d.
void play_terms(const Model& nominal, const Vector6d& approach, const Vector6d& play, Vector6d& coefficient,
                Vector6d& constant, Vector6d& direction) noexcept;

/// The regressors of set.effects() for the stations of `groups` (station_motor: each station's
/// commands): load needs the nominal model's static load, heat the observations' times.
EffectRegressors effect_regressors(const ParameterSet& set, std::span<const Observation> observations,
                                   const ObservationGroups& groups, const std::vector<Vector6d>& station_motor);

/// d A_B / d theta_platform (3 x set.platform_size()) of target t at the pose `fk` with sensitivity
/// `dx_dtheta`, for the commands held fixed: the derivative of where the target is.
Eigen::Matrix<double, 3, Eigen::Dynamic> point_sensitivity(const ParameterSet& set, const FkResult& fk,
                                                           const Eigen::Matrix<double, 6, Eigen::Dynamic>& dx_dtheta,
                                                           const Eigen::VectorXd& theta, int target);

/// Target t of the candidate at the placement x [m, B].
Vector3d target_B(const Model& candidate, const Placement& x, const ParameterSet& set, const Eigen::VectorXd& theta,
                  int target);

/// The residuals of an identification on the groups' mean points, weighted by sqrt(count) so that
/// their squares sum to the cost of all points less the groups' scatter, and their Jacobian
/// (theory §13). Each station's last pose is the next evaluation's start.
class Evaluator {
 public:
  Evaluator(const ParameterSet& set, std::span<const Observation> observations, const ObservationGroups& groups,
            const FkOptions& fk);

  /// Residuals e (3 groups) [m, B] of the parameters theta (tracker frame X_BT given apart) and, if
  /// J is given, their Jacobian (3 groups x set.size(); the rotation as the left perturbation dw).
  /// Stations listed in `skip` (may be empty) get zero rows. Returns Ok or the status of the
  /// candidate model (NonFiniteInput for an invalid one) or of a station's forward kinematics
  /// (failed_station() says which).
  Status evaluate(const Eigen::VectorXd& theta, double sign, const RigidTransform& X_BT, Eigen::VectorXd& e,
                  Eigen::MatrixXd* J, std::span<const char> skip = {});

  /// Number of groups (residual rows / 3).
  std::size_t group_count() const noexcept { return groups_.station.size(); }
  /// Group g's mean measured point [m, T].
  const Vector3d& mean_T(std::size_t g) const noexcept { return groups_.mean_T[g]; }
  /// Station whose forward kinematics failed last (-1: the candidate model itself).
  int failed_station() const noexcept { return failed_station_; }
  /// The poses of the last evaluation, per station.
  const std::vector<Placement>& poses() const noexcept { return poses_; }
  /// The legs' effects at the stations; a status other than Ok fails every evaluation.
  const EffectRegressors& effects() const noexcept { return effects_; }
  /// The candidate model of the last evaluation (empty if it was invalid).
  const std::optional<Model>& candidate() const noexcept { return candidate_; }

 private:
  const ParameterSet& set_;
  std::span<const Observation> observations_;
  const ObservationGroups& groups_;
  FkOptions fk_options_;
  std::vector<Vector6d> station_motor_;
  EffectRegressors effects_;
  std::vector<Placement> poses_;
  std::optional<Model> candidate_;
  int failed_station_ = -1;
};

}  // namespace hexatwist::detail
