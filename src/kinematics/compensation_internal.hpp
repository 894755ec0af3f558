// SPDX-License-Identifier: BSD-3-Clause
// Internal: the second half of motor_commands, shared with the batch path (batch.cpp).
#pragma once

#include "hexatwist/kinematics/compensation.hpp"

namespace hexatwist::detail {

/// What motor_commands does for a finite pose once its pass in registers has failed a test:
/// inverse kinematics into a LegState, check_limits (which names the leg and limit), the twist,
/// Eq. (12) and the stroke test, then the drives' reference and scale. `compensated` is
/// strategy == Compensated and model.has_twist(). `command` is written only when Ok.
[[nodiscard]] Status commands_through_state(const Model& model, const Pose& pose, bool compensated, Vector6d& command,
                                            LimitReport& report) noexcept;

}  // namespace hexatwist::detail
