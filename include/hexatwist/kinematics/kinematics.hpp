// SPDX-License-Identifier: BSD-3-Clause
// Inverse kinematics, paper Eq. (1)-(4): leg vectors, lengths and unit axes for a pose.
#pragma once

#include "hexatwist/kinematics/model.hpp"
#include "hexatwist/kinematics/pose.hpp"
#include "hexatwist/status.hpp"

namespace hexatwist {

/// Per-leg inverse-kinematics state for one pose (caller-owned workspace, filled by
/// inverse_kinematics; uninitialised before). Row i of each LegVectors is leg i, so
/// `state.s_B.row(i).transpose()` is leg i's axis as a Vector3d.
struct LegState {
  Matrix3d R_BP;               ///< platform orientation [-, B]
  LegVectors leg_B;            ///< leg vector L_i, base joint to platform joint [m, B]
  LegVectors s_B;              ///< unit leg axis L_i/|L_i| [-, B]
  LegVectors arm_B;            ///< R_BP * arm_P: pivot to platform joint [m, B]
  LegVectors axis_platform_B;  ///< R_BP * jd_P, Eq. (6) [-, B]
  Vector6d length;             ///< |L_i|, Eq. (4) [m]
};

/// Inverse kinematics, Eq. (1)-(4). Returns NonFiniteInput for a non-finite pose (or one so far that the lengths
/// overflow); a zero-length leg is reported as StrokeBelowMin. Limits are not checked here (see limits.hpp).
[[nodiscard]] Status inverse_kinematics(const Model& model, const Placement& x, LegState& out) noexcept;

/// Inverse kinematics for a roll-pitch-yaw pose.
[[nodiscard]] Status inverse_kinematics(const Model& model, const Pose& pose, LegState& out) noexcept;

/// Jacobian of the leg lengths with respect to the platform twist (dt [m, B], dw [rad, B]):
/// row i is [s_i^T, (arm_i x s_i)^T], for the perturbation t += dt, R_BP = exp(dw) R_BP.
void length_jacobian(const LegState& state, Matrix6d& J_length_x) noexcept;

/// Position of a platform point p_P [m, P] in the base frame for a placement [m, B].
Vector3d platform_point_B(const Model& model, const Placement& x, const Vector3d& p_P) noexcept;

}  // namespace hexatwist
