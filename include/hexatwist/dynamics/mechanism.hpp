// SPDX-License-Identifier: BSD-3-Clause
// Dynamics of the whole mechanism (docs/theory.md §14): the platform with its payload, the two
// bodies of each leg (housing with the motor on the base U-joint, rod with the nut on the platform
// U-joint), the rotor and screw spinning about the leg, screw efficiency and friction. The rods
// spin with the twist, and the screw's angle in its nut is the motor's angle plus the twist.
//
// Coordinates: the platform's velocity [v; w] as in length_jacobian (v of the pivot [m/s, B], w
// the angular velocity [rad/s, B]); the six motor angles follow from the pose (inverse
// kinematics and the twist), so the mechanism has six degrees of freedom. Every function here is
// noexcept and allocation-free.
#pragma once

#include "hexatwist/dynamics/rig.hpp"
#include "hexatwist/kinematics/forward.hpp"

namespace hexatwist {

/// The platform's motion at one instant.
struct PlatformMotion {
  Placement placement;                       ///< pose [m, B]
  Vector6d velocity = Vector6d::Zero();      ///< [v of the pivot; w] [m/s, rad/s, B]
  Vector6d acceleration = Vector6d::Zero();  ///< time derivative of velocity [m/s^2, rad/s^2, B]
};

/// The motion of a pose given in roll-pitch-yaw with its time derivatives: w = E(rpy) rpy',
/// w' = E rpy'' + E' rpy' (docs/theory.md §14).
PlatformMotion platform_motion(const Pose& pose, const Vector6d& pose_rate, const Vector6d& pose_acceleration) noexcept;

/// Motor torques for a motion, and what they are made of. The six contributions add up to
/// `torque` (to rounding): each is J_phi^-T times that part of the generalised force.
struct InverseDynamics {
  Vector6d torque;            ///< motor torque [N m], positive in the sense that lengthens the leg
  Vector6d angle;             ///< motor angle relative to home [rad]
  Vector6d speed;             ///< motor speed [rad/s]
  Vector6d acceleration;      ///< motor acceleration [rad/s^2]
  Vector6d power;             ///< torque * speed [W]; negative = the load drives the motor
  Vector6d gravity;           ///< share of gravity (platform, payload and legs) [N m]
  Vector6d platform_inertia;  ///< share of the platform's inertia, linear in the acceleration [N m]
  Vector6d velocity_product;  ///< share of the velocity-product (Coriolis, centripetal, gyroscopic) terms of the
                              ///< platform and the leg bodies [N m]
  Vector6d legs;              ///< share of the leg bodies' inertia, linear in the acceleration [N m]
  Vector6d drives;        ///< share of rotor, gear and screw inertia: all of it, velocity-product part of the motor's
                          ///< acceleration included [N m]
  Vector6d friction;      ///< viscous and dry friction and the screw's efficiency losses [N m]
  Vector6d screw_force;   ///< axial force the nut carries, tension positive [N]
  Vector6d thread_speed;  ///< the nut's sliding along the screw as a motor speed: real length rate / motor gain,
                          ///< the motor speed plus (twist gain / motor gain) * twist rate [rad/s]
  Vector6d thread_dissipation;  ///< power the screw's efficiency loss dissipates in the thread, >= 0 [W]
  LegState legs_state;          ///< inverse kinematics at the pose
};

/// Motor torques for `motion` (Newton-Euler on every body, projected by virtual power;
/// docs/theory.md §14). Returns the status of inverse kinematics or of the twist Jacobian, or
/// SingularJacobian where the motor angles do not determine the pose. Limits are not checked.
[[nodiscard]] Status inverse_dynamics(const Rig& rig, const PlatformMotion& motion, InverseDynamics& out) noexcept;

/// The mechanism's mass matrix in platform coordinates: kinetic energy = 1/2 x'^T M x' with
/// x' = [v; w], every body included (platform, housings, rods, rotors, screws).
[[nodiscard]] Status mechanism_mass_matrix(const Rig& rig, const Placement& placement, Matrix6d& M) noexcept;

/// The generalised force of everything but the motors and friction at zero acceleration:
/// velocity-product terms minus gravity, so that M x'' + bias = J_phi^T (tau - friction).
[[nodiscard]] Status mechanism_bias(const Rig& rig, const Placement& placement, const Vector6d& velocity,
                                    Vector6d& bias) noexcept;

/// Jacobian of the motor angles: phi' = J_phi x' [rad per m, rad per rad].
[[nodiscard]] Status motor_jacobian(const Rig& rig, const LegState& legs, Matrix6d& J_phi) noexcept;

/// Motor angles relative to home for a placement (inverse kinematics and the twist) [rad].
[[nodiscard]] Status motor_angles(const Rig& rig, const Placement& placement, Vector6d& angle) noexcept;

/// Friction torque at each motor shaft for motor speeds `speed` [rad/s]: viscous and smoothed dry
/// friction, b speed + tau_c tanh(speed / w_f) [N m] (docs/theory/dynamics.md §14).
Vector6d drive_friction(const Rig& rig, const Vector6d& speed) noexcept;

/// The screw's efficiency loss in each thread, a torque pair on screw and nut [N m, at the motor
/// shaft], for the nut's sliding `thread_speed` (InverseDynamics::thread_speed) [rad/s] and the
/// torque the screw passes to the load `screw_torque` [N m]: |tau_s| tanh(w_t / w_f) times
/// 1/eta - 1 where the power through the thread tau_s w_t is positive (the screw drives) and
/// 1 - eta' where it is negative (driven back), so that loss * thread_speed >= 0 is the power the
/// thread dissipates (theory §14). Its share of the motor torques is J_phi^-T of the pair's
/// generalised force, sum_i loss_i / c_i [s_i; a_i x s_i].
Vector6d thread_loss(const Rig& rig, const Vector6d& thread_speed, const Vector6d& screw_torque) noexcept;

/// Platform acceleration for motor torques `torque` (at the shaft, friction not included: pass
/// the net torque), from M x'' = J_phi^T torque - bias.
[[nodiscard]] Status forward_dynamics(const Rig& rig, const Placement& placement, const Vector6d& velocity,
                                      const Vector6d& torque, Vector6d& acceleration) noexcept;

/// Kinetic energy of every body [J].
[[nodiscard]] Status kinetic_energy(const Rig& rig, const Placement& placement, const Vector6d& velocity,
                                    double& energy) noexcept;

/// Potential energy in gravity of every body, zero at home [J].
[[nodiscard]] Status potential_energy(const Rig& rig, const Placement& placement, double& energy) noexcept;

/// Peak torque the motor can give at `speed` (its intermittent envelope) [N m]: servo.torque_limit
/// up to servo.peak_corner_speed, then falling linearly to servo.peak_torque_at_max_speed at
/// servo.max_speed; 0 beyond.
double peak_torque_at(const ServoSpec& servo, double speed) noexcept;

}  // namespace hexatwist
