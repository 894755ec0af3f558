// SPDX-License-Identifier: BSD-3-Clause
// One position loop per leg on the motor encoder (the paper's Fig. 4): PID with anti-windup and
// feed-forward, and the drives' dynamics integrated with fixed-step RK4 (docs/theory.md §9).
#pragma once

#include "hexatwist/dynamics/rig.hpp"

namespace hexatwist {

/// The six drives: motor angles relative to home and their speeds (the plant's state).
struct DriveState {
  Vector6d angle = Vector6d::Zero();   ///< motor angle; motor-side length = home length + motor_gain * angle [rad]
  Vector6d speed = Vector6d::Zero();   ///< motor speed [rad/s]
  Vector6d torque = Vector6d::Zero();  ///< torque the motor produces (lags the command by the current loop) [N m]
};

/// What the controller is asked to follow at one tick, at the motor shaft.
struct ServoReference {
  Vector6d angle = Vector6d::Zero();         ///< [rad]
  Vector6d speed = Vector6d::Zero();         ///< [rad/s]
  Vector6d acceleration = Vector6d::Zero();  ///< [rad/s^2]
};

/// The controller's memory.
struct ControllerState {
  Vector6d integral = Vector6d::Zero();       ///< integral of the angle error [rad s]
  Vector6d last_measured = Vector6d::Zero();  ///< encoder reading of the previous tick [rad]
  int saturated_ticks = 0;                    ///< ticks on which some leg's torque hit the limit
};

/// Encoder reading of the motor angles: whole counts, rounded towards -inf [rad].
void read_encoder(const Rig& rig, const Vector6d& angle, Vector6d& measured) noexcept;

/// Starts the controller settled at `measured` with its integrator holding `holding_torque` [N m]
/// (a drive that has been standing still under the load).
void start_controller(const Rig& rig, const Vector6d& measured, const Vector6d& holding_torque,
                      ControllerState& state) noexcept;

/// One control update: torque = kp e + ki int(e) + kd (speed_ref - speed_measured)
/// + velocity_feedforward b speed_ref + acceleration_feedforward J_nominal acceleration_ref,
/// clamped to the torque limit. The integrator stops while the output is saturated in the
/// direction the error pushes (anti-windup) and never holds more than the torque limit.
/// The measured speed is the encoder difference over one control period.
void update_controller(const Rig& rig, const ServoReference& reference, const Vector6d& measured,
                       ControllerState& state, Vector6d& torque) noexcept;

/// Advances the drives by one control period (rig.substeps() RK4 steps) under a constant torque
/// command and load: A theta'' = tau_m - b theta' - tau_c tanh(theta'/w_f) + load_torque, with the
/// motor torque tau_m following the command with the current loop's lag, and `inverse_inertia` =
/// A^-1 (drive inertia on the diagonal plus the reflected load, held over the period) [1/(kg m^2)].
void integrate_drives(const Rig& rig, const Matrix6d& inverse_inertia, const Vector6d& load_torque,
                      const Vector6d& torque, DriveState& drives) noexcept;

}  // namespace hexatwist
