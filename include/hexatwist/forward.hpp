// Forward kinematics: the pose for given leg lengths, by Newton's method on R^3 x SO(3), either
// from geometric lengths or from motor-side lengths with the twist included.
#pragma once

#include "hexatwist/kinematics.hpp"

namespace hexatwist {

/// What the given lengths are.
enum class LengthKind {
  Geometric,  ///< joint-to-joint leg lengths: solve |L_i(q)| = l_i
  Motor,      ///< motor-side lengths: solve |L_i(q)| - length_offset_i - twist_gain_i * dtheta_i(q) = m_i
};

/// Newton settings.
struct FkOptions {
  int max_iterations = 30;     ///< Newton iterations before NoConvergence
  double tolerance = 1e-12;    ///< max |residual| accepted [m]
  double singular_ratio = 1e-12;  ///< smallest |pivot| ratio of the LU before SingularJacobian
};

/// Result of forward kinematics (caller-owned).
struct FkResult {
  Placement placement;       ///< solution as displacement + rotation matrix
  Pose pose;                 ///< the same as roll-pitch-yaw
  int iterations = 0;        ///< Newton iterations taken
  double residual = 0.0;     ///< max_i |residual_i| at `placement` [m]
  LegState legs;             ///< inverse kinematics at the solution
};

/// Jacobian of the lengths of `kind` at the state `legs` (inverse kinematics done) for the
/// perturbation of length_jacobian: the length Jacobian, minus diag(twist_gain) times the twist
/// Jacobian for motor-side lengths. Returns SingularBase/SingularPlatform as twist_jacobian does.
[[nodiscard]] Status length_jacobian(const Model& model, const LegState& legs, LengthKind kind, Matrix6d& J) noexcept;

/// Residual f(x) = g(x) - lengths, with g the geometric or motor-side lengths, and its Jacobian
/// J_f_x for the perturbation t += dt, R = exp(dw) R. The motor-side rows include the twist's
/// derivative.
[[nodiscard]] Status fk_residual(const Model& model, const Placement& x, const Vector6d& lengths,
                                 LengthKind kind, LegState& legs, Vector6d& f, Matrix6d* J_f_x) noexcept;

/// Forward kinematics from `guess` (home by default in the CLI). Returns Ok, NoConvergence,
/// SingularJacobian, SingularBase/SingularPlatform (an iterate crossed a U-joint singularity) or
/// NonFiniteInput; `out.residual` and `out.iterations` are set in every case.
[[nodiscard]] Status forward_kinematics(const Model& model, const Vector6d& lengths, LengthKind kind,
                                        const Placement& guess, FkResult& out,
                                        const FkOptions& options = {}) noexcept;

}  // namespace hexatwist
