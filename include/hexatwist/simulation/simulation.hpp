// SPDX-License-Identifier: BSD-3-Clause
// Closed-loop simulation of the platform under its six servo loops (the paper's §3-4, Fig. 4):
// the commands of a trajectory, the drives, the load, and the real pose with the twist included.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "hexatwist/dynamics/rig.hpp"
#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/kinematics/forward.hpp"
#include "hexatwist/motion/trajectory.hpp"

namespace hexatwist {

/// How to run one simulation.
struct SimulationOptions {
  Strategy strategy = Strategy::Compensated;  ///< how the motor-side targets are formed
  /// false: the plant's legs do not twist (real length = motor-side length) and the targets are the
  /// IK lengths: the servo's own tracking error, with no twist in it ("tracking only").
  bool twist_in_plant = true;
  /// Called now and then with (ticks done, ticks in all); may be empty.
  std::function<void(std::size_t, std::size_t)> progress;
};

/// One control tick. Lengths are absolute [m]; poses are [x, y, z, roll, pitch, yaw] [m, rad].
struct SimulationSample {
  double time = 0.0;                    ///< [s]
  Vector6d desired = Vector6d::Zero();  ///< commanded pose
  Vector6d actual = Vector6d::Zero();   ///< real pose (twist-aware forward kinematics of the motors)
  Vector6d command = Vector6d::Zero();  ///< motor-side target of each leg
  Vector6d encoder = Vector6d::Zero();  ///< motor-side length as the encoder reads it
  Vector6d motor = Vector6d::Zero();    ///< true motor-side length
  Vector6d length = Vector6d::Zero();   ///< real leg length, joint to joint
  Vector6d twist = Vector6d::Zero();    ///< real twist relative to home [rad]
  Vector6d torque = Vector6d::Zero();   ///< motor torque [N m]
  double error = 0.0;                   ///< distance of the observation point from where it was commanded [m]
  double error_twist_only = 0.0;        ///< the same with perfect servos (motors exactly at the target) [m]
};

/// Where and why a trajectory cannot be run, or a simulation stopped.
struct SimulationIssue {
  Status status = Status::Ok;  ///< a limit (MotorSpeedAboveMax, TorqueAboveMax included), or a numerical failure
  std::size_t index = 0;       ///< sample of the trajectory
  double time = 0.0;           ///< its time [s]
  LimitReport limit;           ///< leg, value and bound (limits; motor speed [rad/s]; holding torque [N m])
};

/// Motor torque that holds the whole mechanism standing still at `pose` [m, rad]: gravity's share of
/// the inverse dynamics (platform, payload and leg bodies; theory §14) [N m], positive where the
/// motor pushes the leg longer. What check_trajectory compares with servo.torque_limit, and what
/// `hexatwist config` shows at home. Returns the status of inverse_dynamics.
[[nodiscard]] Status holding_torque(const Rig& rig, const Pose& pose, Vector6d& torque) noexcept;

/// Checks the whole trajectory before anything runs: every pose inside the limits, both
/// commands inside the stroke, no motor faster than servo.max_speed, and no motor that could not
/// even hold the load standing still (static torque above servo.torque_limit). Returns the first
/// violation (Ok if none). Nothing is simulated.
[[nodiscard]] Status check_trajectory(const Rig& rig, const Trajectory& trajectory, SimulationIssue& issue);

/// Simulates the trajectory at the rig's control rate (one sample per trajectory sample; the
/// trajectory's period must equal the control period). Starts settled at the first pose. Before
/// the first tick, the commands this run will send are checked at every sample as check_trajectory
/// does (pose limits, stroke, motor speed, holding torque), so nothing runs past a limit; on any
/// failure `issue` says where, `samples` holds the ticks done so far, and the status is returned.
/// A trajectory of more than kMaxTrajectorySamples poses is InvalidArgument (nothing is allocated).
[[nodiscard]] Status simulate(const Rig& rig, const Trajectory& trajectory, const SimulationOptions& options,
                              std::vector<SimulationSample>& samples, SimulationIssue& issue);

}  // namespace hexatwist
