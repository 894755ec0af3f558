// SPDX-License-Identifier: BSD-3-Clause
// What a real leg adds to its geometry (docs/theory/kinematics.md §4b): it shortens under its
// axial load (stiffness), grows with its temperature (thermal expansion of the length between the
// joints and of the screw's lead), and its nut lags the motor by half its play in the direction of
// the last motion. Each acts relative to the reference state (home after homing, the reference
// temperature, the configuration's static load), so the commands there are those without it; a
// model without these fields gives the same results, bit for bit, as before they existed.
//
// The leg's real length, joint to joint, for the nut's travel u (the drives' motor-side length
// through their scale, theory §4):
//   l = u + offset + k dtheta + E,
//   E = c (F - F_ref) + dT (a_L l_home + a_P (u - h + k dtheta)) - (b / 2)(d - d_home),
// with c = 1 / stiffness, F the axial force (tension positive) and F_ref its value at home under
// the configuration's load, dT the temperature above the reference, a_L and a_P the length's and
// the lead's expansion, h the drive's reference, b the play and d the direction of the last motion
// (+1 lengthening). Every function here is noexcept and allocates nothing.
#pragma once

#include <limits>
#include <string_view>

#include "hexatwist/kinematics/kinematics.hpp"

namespace hexatwist {

/// The legs' static axial forces at the pose of `legs` under `load` (model.spec().static_load, or
/// another payload), tension positive (gravity compresses the legs: negative) [N]: F = J^-T G, J
/// the length Jacobian and G the generalised force of gravity on the load and on every leg's
/// housing and rod (theory §4b). Returns InvalidArgument without a load (present false),
/// SingularJacobian where J is singular, NonFiniteInput for a non-finite result.
[[nodiscard]] Status static_leg_forces(const Model& model, const StaticLoadSpec& load, const LegState& legs,
                                       Vector6d& force) noexcept;

/// The conditions the legs work in besides the pose.
struct LegInputs {
  /// Each leg's axial force, tension positive [N]; NaN = the static force of the model's load at
  /// the pose (the trajectory's inertia left out).
  Vector6d force = Vector6d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// Each leg's temperature [degC]; NaN = the model's reference temperature (no expansion).
  Vector6d temperature = Vector6d::Constant(std::numeric_limits<double>::quiet_NaN());
};

/// Why `inputs` cannot be used (empty when they can): a temperature outside kMinTemperature to
/// kMaxTemperature (NaN allowed: the reference) or an infinite force (NaN allowed: the static
/// force). The commands and forward kinematics refuse such inputs (InvalidArgument for a
/// temperature out of range, NonFiniteInput for an infinite value), the stream's settings too.
[[nodiscard]] std::string_view check_leg_inputs(const LegInputs& inputs) noexcept;

/// The direction of each leg's last motion, for its play (caller-owned: one per stream, controller
/// or C API handle; no sharing between threads).
struct PlayState {
  bool started = false;                   ///< start_play was called
  Vector6d direction = Vector6d::Zero();  ///< +1 lengthening, -1 shortening [-]
  Vector6d last = Vector6d::Zero();       ///< the last travel before its play term [m]
};

/// Starts at the drives' reference after homing: the travel `travel` [m] (the model's
/// home_command, or where the machine stands), each leg's direction its home_direction.
void start_play(const Model& model, const Vector6d& travel, PlayState& play) noexcept;

/// Each leg's direction for a travel `travel` before its play term [m]: the sense of its change
/// from play.last, kept where it does not change; from the reference (home_command, home_direction)
/// when play has not started: the approach straight from home. Does not change `play`.
Vector6d play_direction(const Model& model, const PlayState& play, const Vector6d& travel) noexcept;

/// Moves `play` on to `travel` [m] with the directions `direction` (play_direction's).
void advance_play(PlayState& play, const Vector6d& travel, const Vector6d& direction) noexcept;

/// The real nuts behind their motors (a plant: a simulation, a synthetic machine), as a dead band:
/// each nut's lag g = nut - motor in [-b/2, b/2] stays while the motor moves inside the gap and is
/// dragged once it crosses it; homing leaves it at -(b/2) d_home. Caller-owned.
struct NutGap {
  bool started = false;
  Vector6d gap = Vector6d::Zero();   ///< g [m]
  Vector6d last = Vector6d::Zero();  ///< the motor-side length it last followed [m]
};

/// Moves `nuts` on to the motor-side lengths `motor` [m] (the first call starts where homing left
/// them, at the drives' reference home_command, and moves them from there as the commands'
/// start_play does) and returns each leg's play direction for forward kinematics, -g / (b/2) in [-1, 1]
/// (home_direction where a leg has no play): the effect's term -(b/2)(d - d_home) is then g - g_home.
Vector6d follow_nuts(const Model& model, const Vector6d& motor, NutGap& nuts) noexcept;

/// The same with the legs at `temperature` [degC]: a warm screw's longer lead moves the thread by
/// the motor-side change times 1 + a_P dT, so that a smaller motor-side change crosses the gap (and
/// by the drive's scale, lead / drive_lead, at any temperature).
Vector6d follow_nuts(const Model& model, const Vector6d& motor, const Vector6d& temperature, NutGap& nuts) noexcept;

/// What the effects change at one pose, leg by leg.
struct LegEffects {
  Vector6d force = Vector6d::Zero();        ///< axial force used [N]
  Vector6d temperature = Vector6d::Zero();  ///< temperature used [degC]
  Vector6d direction = Vector6d::Zero();    ///< direction of the last motion used [-]
  Vector6d load = Vector6d::Zero();         ///< c (F - F_ref) [m]
  Vector6d thermal = Vector6d::Zero();      ///< dT (a_L l_home + a_P (u - h + k dtheta)) [m]
  Vector6d play = Vector6d::Zero();         ///< -(b / 2)(d - d_home) [m]
  Vector6d total = Vector6d::Zero();        ///< real minus rigid length: the sum [m]
};

/// The forces and temperatures `inputs` resolves to at the pose of `legs`: the static forces of
/// the model's load where a force is NaN (only where a leg has a stiffness; 0 otherwise), the
/// reference where a temperature is NaN. Returns NonFiniteInput for an infinite input, or the
/// status of static_leg_forces.
[[nodiscard]] Status resolve_inputs(const Model& model, const LegState& legs, const LegInputs& inputs, Vector6d& force,
                                    Vector6d& temperature) noexcept;

/// The travel u [m] that gives the real lengths a rigid leg in the reference state has at the
/// travel `u0` [m] (the twist-compensated travel, theory §4), under the force `force` [N], the
/// temperature `temperature` [degC] and the direction `direction`, with the twist term
/// `twist_term` = k dtheta [m]; `effects` (may be null) receives the parts at u. Exact, the lead's
/// expansion included: effect_lengths at the result gives back u0 - u.
void travel_under_effects(const Model& model, const Vector6d& u0, const Vector6d& twist_term, const Vector6d& force,
                          const Vector6d& temperature, const Vector6d& direction, Vector6d& travel,
                          LegEffects* effects) noexcept;

/// The effects' real-minus-rigid length E [m] at the travel `travel` [m] (the other inputs as
/// travel_under_effects): what a rigid leg's forward kinematics adds to the nut's travel.
void effect_lengths(const Model& model, const Vector6d& travel, const Vector6d& twist_term, const Vector6d& force,
                    const Vector6d& temperature, const Vector6d& direction, LegEffects& effects) noexcept;

}  // namespace hexatwist
