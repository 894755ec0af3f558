// SPDX-License-Identifier: BSD-3-Clause
// The legs' axial forces along a known motion (docs/theory/kinematics.md §4b, theory §14): the
// static load at the pose (static_leg_forces, kinematics/leg_effects.hpp) plus what the motion's
// accelerations and velocities add, from the whole mechanism's inverse dynamics. What a leg's
// stiffness turns into a deflection when the trajectory is known ahead (a planned run, a study, a
// simulation); a command that knows only the pose compensates the static load alone.
#pragma once

#include <cstddef>
#include <vector>

#include "hexatwist/dynamics/mechanism.hpp"
#include "hexatwist/motion/trajectory.hpp"

namespace hexatwist {

/// The motion at sample `k` of `trajectory` (k < its size, at least 2 samples): the pose with its
/// rate by central differences (one-sided at the ends) and its acceleration by the second
/// difference (zero at the ends), as the `dynamics` command and the simulation's references take
/// them (theory §14).
PlatformMotion trajectory_motion(const Trajectory& trajectory, std::size_t k) noexcept;

/// What the motion adds to each nut's axial force beyond gravity's [N], tension positive: the
/// platform's, the payload's and the leg bodies' inertia and velocity products, at the nut as
/// inverse_dynamics gives them (screw_force less its gravity share). Exactly zero at rest. Returns
/// the status of inverse_dynamics.
[[nodiscard]] Status inertial_leg_forces(const Rig& rig, const PlatformMotion& motion, Vector6d& force) noexcept;

/// Each sample's leg forces [N], tension positive: static_leg_forces under the configuration's
/// static load at the pose plus inertial_leg_forces of trajectory_motion. `force` gets one entry per
/// pose; on a failure, `failed_at` is the sample and the status is that of inverse kinematics,
/// static_leg_forces or inverse_dynamics (InvalidArgument for fewer than 2 samples or a bad dt).
[[nodiscard]] Status trajectory_leg_forces(const Rig& rig, const Trajectory& trajectory, std::vector<Vector6d>& force,
                                           std::size_t& failed_at);

}  // namespace hexatwist
