// SPDX-License-Identifier: BSD-3-Clause
// Forward kinematics: the pose for given leg lengths, by Newton's method on R^3 x SO(3), either
// from geometric lengths or from motor-side lengths with the twist included.
#pragma once

#include <string_view>

#include "hexatwist/kinematics/kinematics.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"

namespace hexatwist {

/// What the given lengths are.
enum class LengthKind {
  Geometric,  ///< joint-to-joint leg lengths: solve |L_i(q)| = l_i
  /// motor-side lengths: solve |L_i(q)| - length_offset_i - twist_gain_i * dtheta_i(q) = u_i, u = the nut's
  /// travel for the drives' commands m (Model::travel_from_motor; u = m without a drive scale)
  Motor,
};

/// Newton settings.
struct FkOptions {
  int max_iterations = 30;   ///< Newton iterations before NoConvergence
  double tolerance = 1e-12;  ///< max |residual| accepted [m]
  /// Smallest min |pivot| / max |pivot| of the elimination of the scaled Jacobian (its columns
  /// in m per m, docs/theory.md §6) before SingularJacobian.
  double singular_ratio = 1e-12;
  /// Step cap (docs/theory.md §5): a Newton step whose translation |dt| or rotation |dw| is
  /// longer than these is shortened, direction kept, before the line search.
  double max_step_translation = 0.5;  ///< longest translation of one step [m]
  double max_step_rotation = 0.5;     ///< largest |dw| of one step (a rotation by 2 atan(|dw|/2) <= |dw|) [rad]
};

/// Largest FkOptions::max_iterations [-].
inline constexpr int kMaxFkIterations = 1000;
/// Largest FkOptions::tolerance: a micrometre of length residual; a looser one would accept poses a
/// laser tracker tells apart [m].
inline constexpr double kMaxFkTolerance = 1e-6;

/// Why `options` are outside their documented ranges, as "field: expected ..." (empty if valid):
/// max_iterations in [1, kMaxFkIterations], tolerance in (0, kMaxFkTolerance] m, singular_ratio in
/// (0, 1e-3], max_step_translation in (0, 10] m, max_step_rotation in (0, pi] rad. NaN is outside
/// every range. forward_kinematics and forward_kinematics_tracked return Status::InvalidArgument
/// for such options (the C API HEXATWIST_INVALID_ARGUMENT; Python and the CLI refuse them with this text).
[[nodiscard]] std::string_view check_fk_options(const FkOptions& options) noexcept;

/// Result of forward kinematics (caller-owned).
struct FkResult {
  Placement placement;    ///< solution as displacement + rotation matrix
  Pose pose;              ///< the same as roll-pitch-yaw
  int iterations = 0;     ///< Newton iterations taken
  double residual = 0.0;  ///< max_i |residual_i| at `placement` [m]
  LegState legs;          ///< inverse kinematics at the solution
  /// Condition number of the Jacobian of the lengths of `kind` at the solution, defined as in
  /// jacobian_condition (limits.hpp) [-]; NaN unless the status is Ok or AssemblyModeChanged.
  double condition = 0.0;
  /// Sign of det of that Jacobian at the solution (+1 or -1; 0 when it was not computed): the
  /// assembly mode [-].
  double det_sign = 0.0;
};

/// Caller-owned state of forward kinematics along a motion (forward_kinematics_tracked).
struct FkTracker {
  Placement last;       ///< the last solution, the next call's start [m, B]
  double det_sign = 0;  ///< its assembly mode, the sign of the Jacobian's determinant [-]
  bool valid = false;   ///< false until the first solution (the start is then home)
};

/// Jacobian of the lengths of `kind` at the state `legs` (inverse kinematics done) for the
/// perturbation of length_jacobian: the length Jacobian, minus diag(twist_gain) times the twist
/// Jacobian for motor-side lengths. Returns SingularBase/SingularPlatform as twist_jacobian does.
[[nodiscard]] Status length_jacobian(const Model& model, const LegState& legs, LengthKind kind, Matrix6d& J) noexcept;

/// Residual f(x) = g(x) - lengths, with g the geometric or motor-side lengths, and its Jacobian
/// J_f_x for the perturbation t += dt, R = exp(dw) R. The motor-side rows include the twist's
/// derivative; with a drive scale they are in the nut's travel (lengths mapped by travel_from_motor).
[[nodiscard]] Status fk_residual(const Model& model, const Placement& x, const Vector6d& lengths, LengthKind kind,
                                 LegState& legs, Vector6d& f, Matrix6d* J_f_x) noexcept;

/// Forward kinematics from `guess` (home by default in the CLI). Returns Ok, NoConvergence,
/// SingularJacobian, SingularBase/SingularPlatform (an iterate crossed a U-joint singularity),
/// NonFiniteInput, or AssemblyModeChanged when the solution's Jacobian determinant has another
/// sign than the guess's (the pose found is on another assembly mode: out.placement holds it, but
/// it is not the pose the guess was near). `out.residual` and `out.iterations` are set in every
/// case; on failure `out.placement` is the best iterate.
[[nodiscard]] Status forward_kinematics(const Model& model, const Vector6d& lengths, LengthKind kind,
                                        const Placement& guess, FkResult& out, const FkOptions& options = {}) noexcept;

/// Forward kinematics of the drives' motor-side lengths `motor` [m] on a model whose legs have
/// effects (leg_effects.hpp): the pose at which the real legs, under `inputs` (forces at the pose,
/// temperatures) and with the play's directions `direction` (null: each leg approached straight
/// from home, the sense of its travel from the drive's reference), have the lengths the drives
/// hold. A fixed point of rigid solves (the effects change with the pose through the forces and the
/// twist only), to 1e-14 m of E; `effects` (may be null) receives them at the solution. Statuses
/// as above. The overload above calls this one with the defaults for motor-side lengths.
[[nodiscard]] Status forward_kinematics(const Model& model, const Vector6d& motor, const LegInputs& inputs,
                                        const Vector6d* direction, const Placement& guess, FkResult& out,
                                        const FkOptions& options = {}, LegEffects* effects = nullptr) noexcept;

/// Forward kinematics along a motion: from tracker.last (home while !tracker.valid), Ok only when
/// converged on the same assembly mode as the tracker's (home's while !valid) and with the
/// Jacobian's condition inside limits.jacobian_condition_max (else PlatformSingularity: near a
/// singularity the lengths no longer tell on which side the platform is). On Ok it stores
/// the solution in `tracker`; on failure it leaves `tracker` as it was and returns the status of
/// forward_kinematics (AssemblyModeChanged, NoConvergence, SingularJacobian, ...).
[[nodiscard]] Status forward_kinematics_tracked(const Model& model, const Vector6d& lengths, LengthKind kind,
                                                FkTracker& tracker, FkResult& out,
                                                const FkOptions& options = {}) noexcept;

/// forward_kinematics_tracked for the motor-side lengths `motor` [m] of a model whose legs have
/// effects, under `inputs` and with the play's directions `direction` (null: from home), solved as
/// the effects' forward_kinematics above; the same acceptance and statuses.
[[nodiscard]] Status forward_kinematics_tracked(const Model& model, const Vector6d& motor, const LegInputs& inputs,
                                                const Vector6d* direction, FkTracker& tracker, FkResult& out,
                                                const FkOptions& options = {}, LegEffects* effects = nullptr) noexcept;

/// Sets `tracker` to a known placement (after homing, or as a fallback start) with that
/// placement's assembly mode for lengths of `kind`. Returns the status of inverse kinematics or of
/// the Jacobian (SingularJacobian where its determinant is zero); `tracker` is unchanged then.
[[nodiscard]] Status fk_tracker_set(const Model& model, const Placement& x, LengthKind kind,
                                    FkTracker& tracker) noexcept;

}  // namespace hexatwist
