// SPDX-License-Identifier: BSD-3-Clause
// The platform with its six drives and the load they carry: everything the closed-loop servo
// simulation needs besides the trajectory (docs/theory.md §9). Immutable and validated, like Model.
#pragma once

#include <limits>

#include "hexatwist/kinematics/model.hpp"

namespace hexatwist {

/// One leg's drive and position controller (all six legs use the same numbers; the lead comes from
/// the Model). Defaults: a 3 kW-class AC servo motor on a 10 mm-lead screw of the seed's size
/// (docs/theory.md §9 says where each number comes from).
struct ServoSpec {
  double motor_inertia = 1.2e-3;     ///< rotor inertia [kg m^2]
  double screw_inertia = 1.0e-3;     ///< screw, coupling and pulleys about the screw axis [kg m^2]
  double viscous_friction = 2.0e-3;  ///< viscous friction at the motor shaft [N m s/rad]
  /// Coulomb (dry) friction of screw, nut and bearings at the motor shaft, smoothed as
  /// coulomb_friction * tanh(speed / friction_speed) [N m].
  double coulomb_friction = 0.3;
  double friction_speed = 0.5;                   ///< speed over which the dry friction changes sign [rad/s]
  double torque_time_constant = 0.5e-3;          ///< current loop: first-order lag of the torque [s]; 0 = instant
  double torque_limit = 28.0;                    ///< peak motor torque [N m]
  double max_speed = 3000.0 * 2.0 * kPi / 60.0;  ///< motor speed limit [rad/s] (3000 rpm)
  /// Torque-speed envelope (mechanism.hpp, peak_torque_at): the peak torque holds up to this speed
  /// [rad/s] ... NaN = derived by the Rig: two thirds of max_speed (2000 of 3000 rpm).
  double peak_corner_speed = std::numeric_limits<double>::quiet_NaN();
  /// ... and falls linearly to this at max_speed [N m]. NaN = 4/7 of torque_limit (16 of 28 N m).
  double peak_torque_at_max_speed = std::numeric_limits<double>::quiet_NaN();
  /// Largest RMS torque the motor carries without overheating [N m]. NaN = torque_limit / 2.95
  /// (9.5 of 28 N m: 3 kW at 3000 rpm).
  double continuous_torque = std::numeric_limits<double>::quiet_NaN();
  double encoder_counts = 1048576;  ///< encoder counts per motor revolution (20 bit)
  double gear_ratio = 1.0;          ///< motor revolutions per screw revolution
  /// Frequency of the closed-loop poles from which the PID gains are derived when kp, ki and kd
  /// are all 0: all three poles at -2 pi pole_frequency on each leg's nominal inertia [Hz]. The
  /// loop's -3 dB bandwidth is then about 3.9 times this (docs/theory.md §9).
  double pole_frequency = 10.0;
  double kp = 0.0;                    ///< proportional gain on the motor angle error [N m/rad]; 0 = from pole_frequency
  double ki = 0.0;                    ///< integral gain [N m/(rad s)]; 0 = from pole_frequency
  double kd = 0.0;                    ///< derivative gain on the motor speed error [N m s/rad]; 0 = from pole_frequency
  double velocity_feedforward = 1.0;  ///< fraction of the model's viscous torque fed forward [-]
  double acceleration_feedforward = 1.0;  ///< fraction of the nominal inertia torque fed forward [-]
};

/// The rigid load on the legs: moving platform plus payload. The legs' own masses are left out.
struct LoadSpec {
  double mass = 1500.0;                                  ///< platform + payload [kg]
  Vector3d center_of_mass_P = Vector3d(0.0, 0.0, 0.15);  ///< centre of mass [m, P]
  Vector3d inertia =
      Vector3d(540.0, 540.0, 1080.0);  ///< principal moments about the centre of mass, along P's axes [kg m^2]
  double gravity = 9.81;               ///< gravitational acceleration, along -z of B [m/s^2]
  /// Products of inertia: the off-diagonal elements (Ixy, Ixz, Iyz) of the inertia tensor about the
  /// centre of mass along P's axes, as they stand in the matrix (-integral of x y dm, ...) [kg m^2].
  Vector3d products = Vector3d::Zero();

  /// The inertia tensor about the centre of mass, along P's axes [kg m^2].
  Matrix3d inertia_tensor() const noexcept {
    Matrix3d I;
    I << inertia.x(), products.x(), products.y(), products.x(), inertia.y(), products.z(), products.y(), products.z(),
        inertia.z();
    return I;
  }
};

/// One body of a leg, axisymmetric about the leg axis.
struct LegBodySpec {
  double mass = 0.0;                ///< [kg]
  double center = 0.0;              ///< centre of mass: distance from the body's own U-joint centre along the leg [m]
  double axial_inertia = 0.0;       ///< about the leg axis [kg m^2]
  double transverse_inertia = 0.0;  ///< about an axis across the leg through the centre of mass [kg m^2]
};

/// The legs' bodies and the screw's efficiency (docs/theory.md §14 says where the defaults come
/// from: a 3 kW electric cylinder of the seed's 1.9 m legs). The rotor and screw inertia are in
/// ServoSpec; the motor sits on the body at the leg's driven side (ModelSpec, LegSpec::driven).
struct MechanismSpec {
  /// Outer tube, motor, belt drive and screw, on the base U-joint.
  LegBodySpec housing{38.0, 0.45, 0.06, 4.5};
  /// Inner tube with nut and rod end, on the platform U-joint (center measured from that joint).
  LegBodySpec rod{16.0, 0.60, 0.015, 2.3};
  double efficiency = 0.90;       ///< screw efficiency, motor driving the load [-]
  double back_efficiency = 0.80;  ///< screw efficiency, load driving the motor [-]
};

/// The static load a rig's legs carry, for their deflection (kinematics/leg_effects.hpp): the
/// load's weight and centre of mass and the legs' bodies. The Rig puts it into its model.
StaticLoadSpec static_load_spec(const LoadSpec& load, const MechanismSpec& mechanism) noexcept;

/// Rates of the simulation.
struct SimulationSpec {
  double control_rate = 1000.0;  ///< servo (controller) rate [Hz]
  double plant_step =
      1e-4;  ///< largest plant integration step [s]; the control period is split into equal steps no longer than this
};

/// Everything a Rig is built from.
struct RigSpec {
  ModelSpec model;
  ServoSpec servo;
  LoadSpec load;
  SimulationSpec simulation;
  MechanismSpec mechanism;
};

/// The validated rig, with the per-leg numbers derived once. Construction throws hexatwist::Error
/// "servo.kp: what" naming the field at fault.
class Rig {
 public:
  explicit Rig(const RigSpec& spec);
  /// A rig from an already validated model (the other parts are validated here).
  Rig(Model model, const ServoSpec& servo, const LoadSpec& load, const SimulationSpec& simulation,
      const MechanismSpec& mechanism = {});

  /// The platform, with the static load of this rig's load and mechanism (static_load_spec).
  const Model& model() const noexcept { return model_; }
  /// The servo, with the envelope's derived values filled in.
  const ServoSpec& servo() const noexcept { return servo_; }
  const LoadSpec& load() const noexcept { return load_; }
  const SimulationSpec& simulation() const noexcept { return simulation_; }
  const MechanismSpec& mechanism() const noexcept { return mechanism_; }

  /// Motor-side length per motor radian, lead_i / (2 pi gear_ratio) [m/rad].
  const Vector6d& motor_gain() const noexcept { return motor_gain_; }
  /// Inertia of one drive at the motor shaft: rotor + screw / gear_ratio^2 [kg m^2].
  double drive_inertia() const noexcept { return drive_inertia_; }
  /// Nominal inertia each motor sees: drive inertia + the load reflected through the leg at home
  /// (diagonal of the leg-space mass matrix) [kg m^2]. Used for feed-forward and for the gains.
  const Vector6d& nominal_inertia() const noexcept { return nominal_inertia_; }
  /// Effective PID gains per leg (given, or derived from pole_frequency).
  const Vector6d& kp() const noexcept { return kp_; }
  const Vector6d& ki() const noexcept { return ki_; }
  const Vector6d& kd() const noexcept { return kd_; }
  /// Control period [s], plant steps per control period, plant step [s].
  double control_period() const noexcept { return control_period_; }
  int substeps() const noexcept { return substeps_; }
  double plant_step() const noexcept { return control_period_ / substeps_; }
  /// One encoder count [rad].
  double encoder_step() const noexcept { return encoder_step_; }

 private:
  void validate_and_derive();
  void derive_drives();  // motor gains, inertias and PID gains from the validated specs

  Model model_;
  ServoSpec servo_;
  LoadSpec load_;
  SimulationSpec simulation_;
  MechanismSpec mechanism_;
  Vector6d motor_gain_;
  Vector6d nominal_inertia_;
  Vector6d kp_, ki_, kd_;
  double drive_inertia_ = 0.0;
  double control_period_ = 0.0;
  int substeps_ = 1;
  double encoder_step_ = 0.0;
};

}  // namespace hexatwist
