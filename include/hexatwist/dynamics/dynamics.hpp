// SPDX-License-Identifier: BSD-3-Clause
// Rigid-body load of the platform seen from the legs: the platform's mass matrix and gravity
// wrench, and both mapped to leg space through the (motor-side) length Jacobian (docs/theory.md §9).
#pragma once

#include "hexatwist/dynamics/rig.hpp"
#include "hexatwist/kinematics/forward.hpp"

namespace hexatwist {

/// Mass matrix of the load for the platform velocity (v of the pivot [m/s, B], w [rad/s, B]), the
/// same coordinates as length_jacobian: kinetic energy = 1/2 [v; w]^T M [v; w].
void platform_mass_matrix(const Model& model, const LoadSpec& load, const Matrix3d& R_BP, Matrix6d& M) noexcept;

/// Generalised gravity force on the load for the same coordinates: [m g; c x m g], with c the
/// centre of mass relative to the pivot [N; N m, B].
void gravity_wrench(const Model& model, const LoadSpec& load, const Matrix3d& R_BP, Vector6d& w) noexcept;

/// The load in leg space, for generalised coordinates m = the six leg lengths of `kind`
/// (geometric, or motor-side with the twist): with J = dm/d[v; w],
/// mass = J^-T M J^-1 [kg], gravity = J^-T w [N] (the force gravity puts along each m).
struct LegDynamics {
  Matrix6d jacobian;  ///< J [-, m]
  Matrix6d mass;      ///< leg-space mass matrix [kg]
  Vector6d gravity;   ///< leg-space gravity force [N]; negative = the leg is compressed
};

/// Fills `out` at the pose of `legs`. Returns SingularJacobian (out unspecified) if J is singular,
/// or the twist Jacobian's SingularBase/SingularPlatform.
[[nodiscard]] Status leg_dynamics(const Model& model, const LoadSpec& load, const LegState& legs, LengthKind kind,
                                  LegDynamics& out) noexcept;

}  // namespace hexatwist
