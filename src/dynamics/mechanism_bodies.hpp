// SPDX-License-Identifier: BSD-3-Clause
// Internal: the bodies of the mechanism as the dynamics' passes over the legs see them
// (docs/theory/dynamics.md §14): each leg's velocity-level state, its accelerations, the
// platform's frame, and the generalised forces of every part. mechanism.cpp and
// mechanism_losses.cpp build on these; not installed.
#pragma once

#include "hexatwist/dynamics/mechanism.hpp"

namespace hexatwist::detail {

// The spin coefficient of a U-joint body (theory §14): for fixed axis j, the body's angular
// velocity about s is f . s' with f = (j.s)(j x s)/|j x s|^2, and its rate of change along s'
// (with j' the axis's own velocity) is f'.
struct SpinCoefficient {
  Vector3d f;
  Vector3d f_dot;
};

// One leg's velocity-level state (theory §14, "Velocities").
struct LegMotion {
  Vector3d s, a;           // unit leg axis; pivot to platform joint [m, B]
  Vector3d u;              // velocity of the platform joint P_i [m/s]
  Vector3d s_dot;          // s'
  Vector3d s_dot_rel;      // s' - w x s: s' seen from the platform
  Vector3d omega;          // the platform's angular velocity [rad/s]
  SpinCoefficient fa, fd;  // spin coefficients of the housing (ja) and the rod (jd)
  Vector3d ja, jd;         // base and platform axes [B]
  bool has_axes = true;
  double l = 0, l_dot = 0;  // length and its rate
  double wh = 0, wr = 0;    // spin rates of housing and rod about s [rad/s]
  double phi_dot = 0;       // motor speed [rad/s]
  double k = 0, c = 0;      // twist gain; motor gain [m/rad]
  double eps = 0;           // rotor sense: rotor spin relative to its body = eps * phi
  bool rotor_on_rod = false;
};

// One leg's accelerations: either the part linear in the platform's acceleration (bias = false;
// `u_dd` and `w_dot` are then that acceleration's), or the velocity-product part (bias = true,
// with u_dd = w x (w x a) and w_dot = 0).
struct LegAcceleration {
  Vector3d u_dd, s_dd;
  double l_dd = 0, wh_dot = 0, wr_dot = 0, phi_dd = 0;
};

// The platform's inertial forces: linear part for (v', w'), velocity part, and gravity.
struct PlatformFrame {
  Vector3d c;  // centre of mass from the pivot [m, B]
  Matrix3d I;  // inertia tensor about the centre of mass [kg m^2, B]
};

// Everything a pass over the legs needs.
struct Mechanism {
  PerLeg<LegMotion> legs;
  PlatformFrame platform;
  Vector3d v, w;
};

// All parts of the generalised force at (legs, velocity, acceleration): each leg's accelerations
// are computed once, split into the part linear in the platform's acceleration and the
// velocity-product part (theory §14).
struct Forces {
  Vector6d gravity = Vector6d::Zero();               // -m g of every body
  Vector6d platform = Vector6d::Zero();              // the platform's inertia, linear part
  Vector6d velocity = Vector6d::Zero();              // velocity products of the platform and the leg bodies
  Vector6d legs = Vector6d::Zero();                  // the leg bodies' inertia, linear part
  Vector6d drives = Vector6d::Zero();                // rotors and screws, linear part (generalised) ...
  Vector6d cphi_drives = Vector6d::Zero();           // ... and through the motor angles
  Vector6d drives_velocity = Vector6d::Zero();       // rotors and screws, velocity products (generalised) ...
  Vector6d cphi_drives_velocity = Vector6d::Zero();  // ... and through the motor angles
  Vector6d phi_dd = Vector6d::Zero();                // motor acceleration [rad/s^2]
  Vector6d phi_dd_bias = Vector6d::Zero();           // its velocity-product part, J_phi' x'
};

/// The legs' velocity-level state at `legs` (inverse kinematics done) and the platform velocity
/// [v; w]; `twist` false for legs that do not twist (real length = motor-side length). Returns
/// SingularBase / SingularPlatform where a U-joint body's spin is undefined.
[[nodiscard]] Status mechanism_motion(const Rig& rig, const LegState& legs, const Vector6d& velocity, Mechanism& mech,
                                      bool twist = true) noexcept;

/// The velocity-level state for another platform velocity at the same pose.
void set_velocity(const Vector6d& velocity, Mechanism& mech) noexcept;

/// Every part of the generalised force at the state and `acceleration`; `linear` false: only
/// gravity and the velocity products (zero platform acceleration).
void all_forces(const Rig& rig, const Mechanism& mech, const Vector6d& acceleration, bool linear, Forces& f) noexcept;

/// The mass matrix, split into the load (platform and leg bodies) and the drives (rotors, screws).
void mass_matrix_of(const Rig& rig, const Mechanism& mech, Matrix6d& M_load, Matrix6d& M_drives) noexcept;

/// J_phi: phi' = J_phi [v; w].
void motor_jacobian_of(const Mechanism& mech, Matrix6d& J) noexcept;

/// The speed of each leg's nut along its screw in motor radians: the real length rate over the
/// motor gain, l' / c = phi' + (k / c) * twist rate [rad/s] (theory §14).
Vector6d thread_speeds(const Mechanism& mech) noexcept;

/// The generalised force of a torque pair `loss` [N m, motor-side] between each leg's screw and
/// nut (the thread's losses, mechanism_losses.cpp): sum_i loss_i / c_i [s_i; a_i x s_i].
Vector6d thread_force(const Mechanism& mech, const Vector6d& loss) noexcept;

}  // namespace hexatwist::detail
