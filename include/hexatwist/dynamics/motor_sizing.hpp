// SPDX-License-Identifier: BSD-3-Clause
// Motor sizing along a trajectory: the inverse dynamics of the whole mechanism (mechanism.hpp) at
// every sample, each motor's torque, speed and power, what its torque is made of, and the check
// against the motor's torque-speed envelope and continuous rating.
// Not real-time: the results are vectors over the trajectory.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>
#include <vector>

#include "hexatwist/dynamics/mechanism.hpp"
#include "hexatwist/kinematics/limits.hpp"
#include "hexatwist/motion/trajectory.hpp"

namespace hexatwist {

/// The six parts of a motor torque, as InverseDynamics splits it; they add up to the torque.
enum class TorqueTerm : int {
  Gravity,          ///< platform, payload and legs held against gravity
  PlatformInertia,  ///< the platform's inertia, linear in its acceleration
  VelocityProduct,  ///< Coriolis, centripetal and gyroscopic terms of every body
  Legs,             ///< the leg bodies' inertia, linear in the acceleration
  Drives,           ///< rotor, gear and screw inertia
  Friction,         ///< viscous and dry friction and the screw's efficiency losses
};
inline constexpr int kTorqueTerms = 6;

/// Stable snake_case name of a term, as written in CSV and JSON ("platform_inertia").
std::string_view to_string(TorqueTerm term) noexcept;

/// One sample of the trajectory.
struct MotorSample {
  double time = 0.0;                           ///< [s]
  Vector6d torque = Vector6d::Zero();          ///< motor torque [N m], positive lengthens the leg
  Vector6d speed = Vector6d::Zero();           ///< motor speed [rad/s]
  Vector6d power = Vector6d::Zero();           ///< torque * speed [W]; negative = the load drives the motor
  std::array<Vector6d, kTorqueTerms> terms{};  ///< the torque's parts, indexed by TorqueTerm [N m]
};

/// The checks of a motor's operating points against its envelope (ServoSpec).
enum class EnvelopeCheck : int {
  None,              ///< no violation
  Speed,             ///< |speed| <= servo.max_speed at every sample
  PeakTorque,        ///< |torque| <= peak_torque_at(servo, |speed|) at every sample
  ContinuousTorque,  ///< RMS torque over the trajectory <= servo.continuous_torque
};

/// Stable snake_case name of a check ("peak_torque").
std::string_view to_string(EnvelopeCheck check) noexcept;

/// Where a motor leaves its envelope. For ContinuousTorque, which is a property of the whole
/// trajectory, the index and time are those of the last sample.
struct EnvelopeViolation {
  EnvelopeCheck check = EnvelopeCheck::None;
  int leg = -1;           ///< 0-based; -1 if none
  std::size_t index = 0;  ///< sample of the trajectory
  double time = 0.0;      ///< [s]
  double value = 0.0;     ///< |speed| [rad/s], |torque| [N m] or RMS torque [N m]
  double bound = 0.0;     ///< the bound it exceeds, in the same unit
};

/// One motor over the whole trajectory. RMS values are over the samples (equal weights: the
/// trajectory is sampled at a fixed period), sqrt(mean(x^2)).
struct MotorSummary {
  double peak_torque = 0.0;         ///< largest |torque| [N m]
  double peak_torque_time = 0.0;    ///< when [s] (the first such sample)
  double rms_torque = 0.0;          ///< RMS torque [N m]
  double peak_speed = 0.0;          ///< largest |speed| [rad/s]
  double peak_speed_time = 0.0;     ///< [s]
  double peak_power = 0.0;          ///< largest torque * speed, the motor driving [W] (0 if it never drives)
  double peak_power_time = 0.0;     ///< [s]
  double energy_driven = 0.0;       ///< integral of max(power, 0) dt: work the motor does [J]
  double energy_regenerated = 0.0;  ///< integral of max(-power, 0) dt: work the load does on the motor [J], >= 0
  /// Share of each term: the RMS of that term divided by the RMS torque, both over the trajectory
  /// [-]. Each share is between 0 and (for terms that cancel each other) above 1; the shares do
  /// not add up to 1 (RMS is not additive), but the squares add up to 1 when the terms are
  /// uncorrelated, and the terms themselves add up to the torque at every sample. 0 for a motor
  /// whose RMS torque is 0.
  std::array<double, kTorqueTerms> share{};
  /// Largest |torque| / peak_torque_at(|speed|) over the samples within servo.max_speed [-]: 1 is
  /// on the peak envelope (the samples beyond max_speed fail the speed check instead).
  double peak_usage = 0.0;
  double peak_usage_time = 0.0;  ///< when [s]
  double speed_usage = 0.0;      ///< peak_speed / servo.max_speed [-]
  double rms_usage = 0.0;        ///< rms_torque / servo.continuous_torque [-]
  EnvelopeViolation violation;   ///< this motor's first violation (check None if none)
};

/// The result of motor sizing. On a failure (status not Ok) `samples` holds the samples before
/// the failing one and the summaries are not computed.
struct MotorSizing {
  std::vector<MotorSample> samples;      ///< one per trajectory sample
  std::array<MotorSummary, 6> motors{};  ///< per leg
  /// The first violation over all motors: the earliest sample, legs in order, at one sample the
  /// speed check before the peak torque check; the continuous torque checks (at the last sample)
  /// come after every pointwise one. check None if every motor stays inside its envelope.
  EnvelopeViolation violation;
  Status status = Status::Ok;    ///< Ok, a pose limit (limit says which), or the failure of inverse_dynamics
  std::size_t failed_index = 0;  ///< sample where status arose
  double failed_time = 0.0;      ///< its time [s]
  LimitReport limit;             ///< leg, value and bound when status is a pose limit
};

/// Motor sizing of `trajectory` on `rig`. At each sample k: the pose rate and acceleration by
/// central differences of the poses, (p[k+1] - p[k-1]) / 2dt and (p[k+1] - 2 p[k] + p[k-1]) / dt^2,
/// one-sided for the rate and 0 for the acceleration at the first and last sample (the motor
/// references of simulate are differentiated alike); platform_motion; the pose limits and both
/// motor commands' stroke (compute_commands; the motor's speed and torque are the envelope's
/// checks here, not limits); then inverse_dynamics. Returns Ok, or the first sample's limit or
/// numerical status (also in out.status, with the sample). The envelope verdict is a result
/// (out.violation), not a status. A trajectory with fewer than 2 poses, a non-positive dt or a
/// non-finite t0 or dt is NonFiniteInput at sample 0; one longer than kMaxTrajectorySamples
/// (check_trajectory_samples) InvalidArgument.
[[nodiscard]] Status size_motors(const Rig& rig, const Trajectory& trajectory, MotorSizing& out);

/// A polyline [speed, torque] in SI units (rad/s, N m).
struct Curve {
  std::vector<double> speed;   ///< [rad/s]
  std::vector<double> torque;  ///< [N m]
};

/// What the torque-speed figure of a motor-sizing run draws, in SI units.
struct TorqueSpeedFigure {
  std::array<Curve, 6> operating;  ///< per motor, its operating point (speed, torque) at each sample
  /// The four-quadrant peak envelope, closed: +peak_torque_at(|speed|) from -max_speed to
  /// +max_speed, down to -peak_torque_at at +max_speed, back to -max_speed and up to the start.
  Curve envelope;
  double continuous_torque = 0.0;  ///< servo.continuous_torque, drawn at +- [N m]
  double max_speed = 0.0;          ///< servo.max_speed, drawn at +- [rad/s]
};

/// The figure's data for `sizing` (its samples may be empty). The envelope is sampled at
/// `envelope_points` speeds per half (at least 2) plus the corner speed exactly.
TorqueSpeedFigure torque_speed_figure(const Rig& rig, const MotorSizing& sizing, int envelope_points = 64);

}  // namespace hexatwist
