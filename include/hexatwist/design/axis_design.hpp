// SPDX-License-Identifier: BSD-3-Clause
// Design of the fixed U-joint axes (docs/theory/design.md §17): the directions of ja (base) and jd
// (platform) that minimise the twist, the length error or the sensitivity to the lead over a
// required workspace, with every limit kept there and the workspace volume kept within a stated
// fraction. Only the axes change; joints, home and limits stay.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "hexatwist/design/workspace_volume.hpp"

namespace hexatwist {

/// How the legs share their axes' turns.
enum class AxisSymmetry {
  Symmetric,  ///< the seed's symmetry (three-fold and mirror): odd legs turn by +a, even legs by -a
  Threefold,  ///< three-fold only: odd legs share one turn, even legs another
  PerLeg,     ///< every leg its own
};

/// What the design minimises: the largest value over the required workspace and the legs of ...
enum class DesignObjective {
  Twist,            ///< ... |twist| [rad]
  LengthError,      ///< ... |length error| = |twist_gain * twist|, Eq. (10) [m]
  LeadSensitivity,  ///< ... |point A's displacement per relative lead error| of the compensated
                    ///< commands, |G_A J^-1 diag(twist_gain) twist| [m]
};

/// Turns of the fixed U-joint axes, per leg, from the model's own (axis_design.hpp's parameters).
struct AxisTurns {
  PerLeg<double> base{};           ///< turn of ja about the base frame's z [rad]
  PerLeg<double> platform{};       ///< turn of jd about the platform frame's z [rad]
  PerLeg<double> base_tilt{};      ///< tilt of ja up out of its horizontal direction [rad]
  PerLeg<double> platform_tilt{};  ///< tilt of jd alike, in the platform frame [rad]
};

/// `axis` tilted by `tilt` towards +z in its vertical plane (no tilt for a vertical axis), then
/// turned by `turn` about z [-].
Vector3d turned_axis(const Vector3d& axis, double turn, double tilt) noexcept;

/// `spec` with every leg's fixed axes turned by `turns` (lengths of the given axes kept).
ModelSpec turned_axes(const ModelSpec& spec, const AxisTurns& turns);

/// The limits whose margins a design reports (each the smallest share of its range left, as
/// nearest_limit measures it, over the poses).
enum class MarginKind : int {
  Stroke,       ///< the legs' lengths, either end
  Command,      ///< the compensated commands (the nut's travel), either end
  Bend,         ///< U-joint bends, base and platform
  Singularity,  ///< U-joint singularity margins, base and platform
  Condition,    ///< the motor-side Jacobian's condition number
};
inline constexpr int kMarginKinds = 5;

/// One limit's margin over a set of poses.
struct LimitMargin {
  double share = INFINITY;  ///< smallest share of the range left (1 far, 0 on the limit) [-]
  LimitReport at;           ///< the limit there: status, leg, value and bound [m, rad or -]
  std::size_t pose = 0;     ///< index of that pose
};

/// The axis error (1 sd, per normal of every fixed axis) at which a design's sensitivity to its
/// U-joint axes is stated (DesignEvaluation::axis_sensitivity) [rad]: 0.1 deg, the tolerance
/// study's default.
inline constexpr double kDesignAxisSigma = 0.1 * kPi / 180.0;

/// A configuration over a required workspace.
struct DesignEvaluation {
  std::size_t poses = 0;              ///< poses evaluated
  std::size_t reached = 0;            ///< of which inside every limit (motor_commands, compensated)
  std::size_t first_refused = 0;      ///< index of the first refused pose (== poses when none)
  LimitReport refused;                ///< its limit
  double max_twist = 0.0;             ///< largest |twist| over the reached poses [rad]
  int twist_leg = -1;                 ///< its leg, 0-based
  std::size_t twist_pose = 0;         ///< its pose
  double max_length_error = 0.0;      ///< largest |length error| [m]
  double max_lead_sensitivity = 0.0;  ///< largest |dA / d(relative lead error)| [m]
  /// What errors of the U-joint axes leave with exact compensation (the controller knowing the
  /// nominal axes): the 95th percentile over the reached poses of point A's linearised error
  /// (tolerance_linear) for kDesignAxisSigma (1 sd) about both normals of every fixed axis [m]
  double axis_sensitivity = NAN;
  std::array<LimitMargin, kMarginKinds> margins{};  ///< by MarginKind
  double volume = NAN;        ///< workspace volume at DesignOptions::volume_rpy [m^3] (NaN: not computed)
  double volume_error = NAN;  ///< its stated error [m^3]
};

/// Settings of the design.
struct DesignOptions {
  DesignObjective objective = DesignObjective::Twist;
  AxisSymmetry symmetry = AxisSymmetry::Symmetric;
  bool tilt = false;                       ///< also search tilts out of the joint planes
  double max_tilt = deg2rad(30.0);         ///< largest tilt searched [rad]
  double grid_step = deg2rad(5.0);         ///< the global grid of in-plane turns [rad]
  double fine_step = deg2rad(0.05);        ///< the local search ends at this step [rad]
  double clearance = 0.0;                  ///< required over the workspace beyond the singularity margin [rad]
  double max_volume_loss = 0.05;           ///< largest fraction of the volume at volume_rpy the design may lose
  Vector3d volume_rpy = Vector3d::Zero();  ///< orientation of the volume kept [rad]
  VolumeOptions volume;                    ///< how it is computed
  int volume_samples = 4000;               ///< positions drawn in its box to steer the search (§17)
  std::uint64_t seed = 1;                  ///< of those positions
  int threads = 1;                         ///< 0 = every core; the result does not depend on it
  /// Called (may be empty) with (steps done, steps in all) at the start (0 done), after each leg's
  /// own search (the bound) and after each group's search, from the calling thread; not part of
  /// the result.
  std::function<void(std::size_t, std::size_t)> progress;
};

/// The most volume_samples a design takes (each is a position tried at every candidate).
inline constexpr int kMaxVolumeSamples = 1000000;
/// The largest clearance a design can be asked for beyond the singularity margin [rad] (80 deg).
inline constexpr double kMaxClearance = 80.0 * kPi / 180.0;

/// Throws ParameterError naming the field for options no design can use: grid_step not in
/// (0, pi/2], fine_step not in (0, grid_step], max_tilt not in [0, pi/2), clearance not in
/// [0, kMaxClearance), max_volume_loss not in [0, 1], volume_rpy not finite, volume.cell not in
/// [0, 1] m ("cell"), volume_samples not in [0, kMaxVolumeSamples], threads < 0. The CLI and
/// Python convert their units and call it; design_axes and evaluate_design run it.
void check_design_options(const DesignOptions& options);

/// The margins, twist, length error and lead sensitivity of `model` over `poses`, and (when
/// `volume` is true) the workspace volume at options.volume_rpy with options.volume.
[[nodiscard]] Status evaluate_design(const Model& model, const std::vector<Pose>& poses, const DesignOptions& options,
                                     bool volume, DesignEvaluation& out);

/// The design found.
struct AxisDesign {
  AxisTurns turns;                                       ///< from the model's axes
  ModelSpec designed;                                    ///< the model's spec with its axes turned
  DesignEvaluation before;                               ///< the model over the required workspace
  DesignEvaluation after;                                ///< the designed one
  double objective_before = 0.0, objective_after = 0.0;  ///< the objective's largest value [rad or m]
  /// How close to the optimum: the twist (or length error) of a leg depends on its own axes only, so
  /// no axes of the kind searched (in the joint planes, or tilted up to max_tilt) do better than the
  /// worst leg's own best, each leg's axes searched alone over the required poses with the volume
  /// left free (as globally as the design's grid and local search find it);
  /// objective_after - objective_bound is what the symmetry and the volume kept cost at most. NaN
  /// for the lead objective, which couples the legs [rad or m].
  double objective_bound = NAN;
  std::size_t evaluations = 0;  ///< candidate axes evaluated
  int attempts = 0;             ///< searches made (a verification that fails tightens the volume budget)
};

/// The axes that minimise options.objective over `required` (poses the model reaches; those it
/// does not are left out) with every limit holding at every one of them, and the volume at
/// options.volume_rpy at least (1 - max_volume_loss) of the model's (docs/theory/design.md §17):
/// a global grid of in-plane turns per group of legs, then a local search (with tilts if asked),
/// each candidate checked on the required poses and steered by positions of the workspace;
/// the best verified with the library's own functions. The model's own axes are the fallback, so
/// the design never does worse. Throws ParameterError for options check_design_options refuses;
/// returns the volume's status when it cannot be computed, or a limit status when the model itself
/// reaches none of `required`.
[[nodiscard]] Status design_axes(const Model& model, const std::vector<Pose>& required, const DesignOptions& options,
                                 AxisDesign& out);

}  // namespace hexatwist
