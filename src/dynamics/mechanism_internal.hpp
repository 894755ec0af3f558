// SPDX-License-Identifier: BSD-3-Clause
// The mechanism's dynamics in the motor angles, as the closed-loop simulation integrates them
// (docs/theory.md §9, §14). Internal: not installed.
#pragma once

#include "hexatwist/dynamics/mechanism.hpp"

namespace hexatwist::detail {

/// The drives' equation A phi'' = tau - friction + load at one state.
struct DriveLoad {
  Matrix6d jacobian;         ///< J_phi
  Matrix6d inverse_inertia;  ///< A^-1 = J_phi M^-1 J_phi^T: A = J_phi^-T M J_phi^-1, every body (rotors and screws
                             ///< included) [1/(kg m^2)]
  Vector6d load;             ///< L = -J_phi^-T bias + A J_phi' x': gravity and velocity products at the motors [N m]
  Vector6d screw_torque;     ///< torque the screws pass to the load at the motor acceleration given [N m]
  Vector6d thread_loss;      ///< the threads' efficiency losses as torques at the motors (thread_loss, theory §14)
                             ///< at the motor speeds and acceleration given [N m]
  Vector6d velocity;         ///< the platform velocity [v; w] for the motor speeds given
};

/// The drives' equation at the state `legs` (inverse kinematics done) with motor speeds `speed`;
/// `twist` false for a plant whose legs do not twist (real length = motor-side length).
[[nodiscard]] Status drive_load(const Rig& rig, const LegState& legs, const Vector6d& speed,
                                const Vector6d& motor_acceleration, bool twist, DriveLoad& out) noexcept;

}  // namespace hexatwist::detail
