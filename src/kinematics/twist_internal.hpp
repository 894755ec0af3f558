// SPDX-License-Identifier: BSD-3-Clause
// Internal: the twist kernels forward kinematics calls directly, and the cheap condition test.
#pragma once

#include "hexatwist/kinematics/twist.hpp"

namespace hexatwist::detail {

/// Jacobian of the motor-side lengths |L_i| - twist_gain_i * dtheta_i for the perturbation of
/// length_jacobian: length_jacobian - diag(twist_gain) * twist_jacobian, in one pass over the
/// legs. Returns SingularBase/SingularPlatform (J unspecified) as twist_jacobian does.
[[nodiscard]] Status motor_length_jacobian(const Model& model, const LegState& state, Matrix6d& J) noexcept;

/// True if the platform Jacobian's condition (jacobian_condition) is proven within the limit by a
/// cheap test (linear_solve.hpp scaled_condition_below); false: not proven, ask jacobian_condition.
[[nodiscard]] bool condition_proven_within(const Model& model, const LegState& state) noexcept;

}  // namespace hexatwist::detail
