// SPDX-License-Identifier: BSD-3-Clause
// A run of straight moves between poses, written as a LinuxCNC G-code program for the kinematics
// module hexatwistkins (integrations/linuxcnc): the program a technician runs on the controller to
// drive a calibration plan (`hexatwist stations --gcode`). Units are LinuxCNC's at its boundary:
// X, Y, Z in mm of the base frame (Z absolute, as [TRAJ] HOME = 0 0 home_height), A, B, C the
// roll, pitch and yaw in degrees (R = Rz*Ry*Rx).
#pragma once

#include <span>
#include <string>
#include <string_view>

#include "hexatwist/kinematics/model.hpp"
#include "hexatwist/motion/trajectory.hpp"

namespace hexatwist {

/// The program of waypoint_trajectory(waypoints, limits, dwell, dt) on `model`, with its timing: a
/// dwell at the first waypoint, then each straight move (G1 in inverse-time mode, G93, so that it
/// takes exactly the planned move's duration, JerkLimitedMove over the distance under `limits`)
/// followed by a dwell (G4) of `dwell` s; exact-stop mode (G61), so that no move is blended into the
/// next. A comment before each move names it ("station 3 of 40") with the planned times of arrival
/// and departure. `title` goes into the first comment. Every number is written with enough digits
/// to read back to 1 pm and 1 ndeg (the joints agree with the plan's to 1e-9 mm). The moves' speeds are the plan's; the
/// controller's own limits
/// ([AXIS_*] MAX_VELOCITY, MAX_ACCELERATION) may make a move slower, never faster.
/// Throws hexatwist::Error as waypoint_trajectory does (fewer than 2 waypoints, non-finite values,
/// bad limits, a negative dwell).
std::string waypoint_program(const Model& model, std::span<const Vector6d> waypoints, const MotionLimits& limits,
                             double dwell, std::string_view title);

}  // namespace hexatwist
