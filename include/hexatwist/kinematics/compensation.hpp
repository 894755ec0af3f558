// SPDX-License-Identifier: BSD-3-Clause
// Length error from the twist (Eq. 10) and the motor commands with and without compensation
// (Eq. 11-12): what the servo must reach on the motor side.
#pragma once

#include <string_view>

#include "hexatwist/kinematics/leg_effects.hpp"
#include "hexatwist/kinematics/limits.hpp"
#include "hexatwist/kinematics/twist.hpp"

namespace hexatwist {

/// How motor-side commands are formed.
enum class Strategy {
  Conventional,  ///< command = IK length - length_offset; the twist (and the legs' effects) ignored
  /// command = IK length - length_offset - twist_gain * dtheta, Eq. (12), less the legs' effects
  /// where the model has them (leg_effects.hpp: deflection, thermal expansion, play)
  Compensated,
};

/// The strategy's name, as the command line, Python and JSON write it: "conventional" or "compensated".
std::string_view to_string(Strategy strategy) noexcept;

/// The strategy `name` names ("conventional" or "compensated") into `out`; false, `out` unchanged,
/// for any other text.
[[nodiscard]] bool parse_strategy(std::string_view name, Strategy& out) noexcept;

/// Length error of each leg caused by its twist, Eq. (10) with the configured sign:
/// real length - motor-side length = twist_gain_i * dtheta_i [m].
void length_error(const Model& model, const Vector6d& dtheta, Vector6d& error) noexcept;

/// Everything about one commanded pose (caller-owned workspace).
struct CommandReport {
  LegState legs;                             ///< inverse kinematics
  Vector6d twist = Vector6d::Zero();         ///< dtheta relative to home [rad]
  Vector6d length_error = Vector6d::Zero();  ///< Eq. (10) [m]
  Vector6d conventional = Vector6d::Zero();  ///< motor-side command, twist ignored [m]
  Vector6d compensated = Vector6d::Zero();   ///< motor-side command, Eq. (12), the legs' effects included [m]
  LimitReport limit;                         ///< first limit violated, if any
  /// The legs' effects at the pose for the compensated command (zero where the model has none).
  LegEffects effects;
};

/// Full computation for a pose: IK, twist, Eq. (10), both commands and the limit check (pose
/// limits, then both commands against the stroke). On any status other than Ok the commands
/// must not be sent.
[[nodiscard]] Status compute_commands(const Model& model, const Pose& pose, CommandReport& out) noexcept;

/// The same under the conditions `inputs`, with the play's direction from `play` (null: each leg
/// approached straight from home, the stateless default of the functions without it). `play` is
/// not moved on (motor_commands does that).
[[nodiscard]] Status compute_commands(const Model& model, const Pose& pose, const LegInputs& inputs,
                                      const PlayState* play, CommandReport& out) noexcept;

/// Real-time path: the motor-side commands for one strategy [m], limits checked. `command` is
/// written only when the result is Ok; `report` says which leg and limit otherwise.
[[nodiscard]] Status motor_commands(const Model& model, const Pose& pose, Strategy strategy, Vector6d& command,
                                    LimitReport& report) noexcept;

/// The real-time command of a model with leg effects (leg_effects.hpp) under `inputs`; `play`
/// (may be null: each leg approached from home) gives the direction of each leg's last motion and
/// is moved on to this command when the result is Ok. For a model without effects, or the
/// Conventional strategy, the command of the overload above.
[[nodiscard]] Status motor_commands(const Model& model, const Pose& pose, Strategy strategy, const LegInputs& inputs,
                                    PlayState* play, Vector6d& command, LimitReport& report) noexcept;

}  // namespace hexatwist
