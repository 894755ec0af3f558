// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/dynamics/rig.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <utility>

#include "dynamics/mechanism_internal.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/kinematics.hpp"

namespace hexatwist {
namespace {

// Messages are "field: what" with the YAML field path (src/io/config.cpp locates them in the file).
[[noreturn]] void fail(const char* field, const std::string& what) { throw Error(fmt::format("{}: {}", field, what)); }

// The plausible range of a quantity (configs/seed.yaml and README's "Platform configuration" list
// them): finite, above `lo` (or at it, when `lo_closed`) and at most `hi`. Finite but absurd values
// (1e300 kg) would overflow the dynamics into NaN or negative gains; they are refused here, at their field.
void in_range(double v, double lo, double hi, const char* field, const char* unit, bool lo_closed = false) {
  if (std::isfinite(v) && (lo_closed ? v >= lo : v > lo) && v <= hi) return;
  const std::string most = std::isinf(hi) ? std::string() : fmt::format(" and at most {:g}", hi);
  fail(field, fmt::format("expected {} {:g}{} {}, got {}", lo_closed ? ">=" : ">", lo, most, unit, v));
}
void positive(double v, double hi, const char* field, const char* unit) { in_range(v, 0.0, hi, field, unit); }
void non_negative(double v, double hi, const char* field, const char* unit) { in_range(v, 0.0, hi, field, unit, true); }

// Largest 2 pi pole_frequency / control rate for which the derived discrete loop keeps its margins.
constexpr double kMaxBandwidthRatio = 0.5;
// Largest distance of a centre of mass from its frame's origin or its joint [m] (model.cpp's bound on lengths).
constexpr double kMaxOffset = 100.0;

void check_servo(const ServoSpec& s) {
  positive(s.motor_inertia, 10.0, "servo.motor_inertia", "kg m^2");
  non_negative(s.screw_inertia, 10.0, "servo.screw_inertia", "kg m^2");
  non_negative(s.viscous_friction, 1e3, "servo.viscous_friction", "N m s/rad");
  non_negative(s.coulomb_friction, 1e4, "servo.coulomb_friction", "N m");
  positive(s.friction_speed, 1e4, "servo.friction_speed", "rad/s");
  non_negative(s.torque_time_constant, 1.0, "servo.torque_time_constant", "s");
  positive(s.torque_limit, 1e5, "servo.torque_limit", "N m");
  positive(s.max_speed, 1e6 * 2.0 * kPi / 60.0, "servo.max_speed", "rad/s (1e6 rpm)");
  if (!std::isfinite(s.encoder_counts) || s.encoder_counts < 1.0 || s.encoder_counts > 4294967296.0 ||
      s.encoder_counts != std::floor(s.encoder_counts))
    fail("servo.encoder_counts",
         fmt::format("expected a whole number of counts per revolution from 1 to 2^32, got {}", s.encoder_counts));
  in_range(s.gear_ratio, 0.01, 1000.0, "servo.gear_ratio", "motor revolutions per screw revolution", true);
  positive(s.pole_frequency, 1e4, "servo.pole_frequency", "Hz");
  non_negative(s.kp, 1e9, "servo.kp", "N m/rad");
  non_negative(s.ki, 1e12, "servo.ki", "N m/(rad s)");
  non_negative(s.kd, 1e6, "servo.kd", "N m s/rad");
  if (!(s.kp == 0.0 && s.ki == 0.0 && s.kd == 0.0) && s.kp == 0.0)
    fail("servo.kp",
         "expected > 0 when ki or kd is given (or leave all three at 0 to derive them from servo.pole_frequency)");
  non_negative(s.velocity_feedforward, 2.0, "servo.velocity_feedforward", "(fraction)");
  non_negative(s.acceleration_feedforward, 2.0, "servo.acceleration_feedforward", "(fraction)");
  positive(s.peak_corner_speed, s.max_speed, "servo.peak_corner_speed", "rad/s (servo.max_speed)");
  non_negative(s.peak_torque_at_max_speed, s.torque_limit, "servo.peak_torque_at_max_speed",
               "N m (the peak torque servo.torque_limit)");
  positive(s.continuous_torque, s.torque_limit, "servo.continuous_torque", "N m (the peak torque servo.torque_limit)");
}

void check_load(const LoadSpec& load) {
  positive(load.mass, 1e6, "load.mass", "kg");
  if (!load.center_of_mass_P.allFinite() || load.center_of_mass_P.cwiseAbs().maxCoeff() > kMaxOffset)
    fail("load.center_of_mass", "expected three finite coordinates within +-100 m");
  for (int i = 0; i < 3; ++i) positive(load.inertia[i], 1e8, "load.inertia", "kg m^2 for each principal moment");
  if (!load.products.allFinite() || load.products.cwiseAbs().maxCoeff() > 1e8)
    fail("load.products_of_inertia", "expected three finite numbers within +-1e8 kg m^2");
  non_negative(load.gravity, 100.0, "load.gravity", "m/s^2");
  // A physical inertia tensor is positive definite and its principal moments obey the triangle
  // inequality (each at most the sum of the other two).
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(load.inertia_tensor(), Eigen::EigenvaluesOnly);
  const Vector3d l = eig.eigenvalues();
  if (!(l.minCoeff() > 0.0) || l[2] > (l[0] + l[1]) * (1.0 + 1e-12))
    fail("load.products_of_inertia",
         fmt::format("the inertia tensor has principal moments {:.6g}, {:.6g}, {:.6g} kg m^2: not a rigid body's "
                     "(each must be > 0 and at most the sum of the other two)",
                     l[0], l[1], l[2]));
}

void check_mechanism(const MechanismSpec& m) {
  const auto body = [](const LegBodySpec& b, const char* mass, const char* center, const char* axial,
                       const char* transverse) {
    non_negative(b.mass, 1e4, mass, "kg");
    if (!std::isfinite(b.center) || std::abs(b.center) > kMaxOffset)
      fail(center, fmt::format("expected a finite distance within +-100 m, got {}", b.center));
    non_negative(b.axial_inertia, 1e4, axial, "kg m^2");
    non_negative(b.transverse_inertia, 1e4, transverse, "kg m^2");
  };
  body(m.housing, "mechanism.housing.mass", "mechanism.housing.center", "mechanism.housing.axial_inertia",
       "mechanism.housing.transverse_inertia");
  body(m.rod, "mechanism.rod.mass", "mechanism.rod.center", "mechanism.rod.axial_inertia",
       "mechanism.rod.transverse_inertia");
  for (const auto& [v, field] :
       {std::pair{m.efficiency, "mechanism.efficiency"}, std::pair{m.back_efficiency, "mechanism.back_efficiency"}})
    positive(v, 1.0, field, "(a fraction)");
}

// The substeps of the plant per control period.
int check_simulation(const SimulationSpec& sim) {
  in_range(sim.control_rate, 10.0, 1e5, "simulation.control_rate", "Hz", true);
  const double period = 1.0 / sim.control_rate;
  positive(sim.plant_step, INFINITY, "simulation.plant_step", "s");
  if (sim.plant_step > period * (1.0 + 1e-12))
    fail("simulation.plant_step", fmt::format("{} s is longer than the control period {} s", sim.plant_step, period));
  // Counted in double and checked before the conversion: a tiny step (1e-40 s) would overflow an int.
  const double substeps = std::ceil(1.0 / sim.control_rate / sim.plant_step * (1.0 - 1e-12));
  if (!(substeps <= 10000.0))
    fail("simulation.plant_step", fmt::format("{} s gives more than 10000 steps per control period", sim.plant_step));
  return static_cast<int>(substeps);
}

bool same_load(const StaticLoadSpec& a, const StaticLoadSpec& b) {
  return a.present == b.present && a.gravity == b.gravity && a.mass == b.mass &&
         a.center_of_mass_P == b.center_of_mass_P && a.rod_mass == b.rod_mass && a.leg_moment == b.leg_moment;
}

}  // namespace

StaticLoadSpec static_load_spec(const LoadSpec& load, const MechanismSpec& mechanism) noexcept {
  StaticLoadSpec s;
  s.present = true;
  s.gravity = load.gravity;
  s.mass = load.mass;
  s.center_of_mass_P = load.center_of_mass_P;
  s.rod_mass = mechanism.rod.mass;
  s.leg_moment = mechanism.housing.mass * mechanism.housing.center - mechanism.rod.mass * mechanism.rod.center;
  return s;
}

namespace {
// The model of a rig's specification, with the rig's static load (a stiffness needs it at once).
ModelSpec with_static_load(const RigSpec& spec) {
  check_load(spec.load);  // named as load.* and mechanism.* before the model sees them
  check_mechanism(spec.mechanism);
  ModelSpec model = spec.model;
  model.static_load = static_load_spec(spec.load, spec.mechanism);
  return model;
}
}  // namespace

Rig::Rig(const RigSpec& spec)
    : Rig(Model(with_static_load(spec)), spec.servo, spec.load, spec.simulation, spec.mechanism) {}

Rig::Rig(Model model, const ServoSpec& servo, const LoadSpec& load, const SimulationSpec& simulation,
         const MechanismSpec& mechanism)
    : model_(std::move(model)), servo_(servo), load_(load), simulation_(simulation), mechanism_(mechanism) {
  validate_and_derive();
}

void Rig::validate_and_derive() {
  // The envelope's values not given follow the peak torque and speed (rig.hpp).
  if (std::isnan(servo_.peak_corner_speed)) servo_.peak_corner_speed = servo_.max_speed * (2.0 / 3.0);
  if (std::isnan(servo_.peak_torque_at_max_speed)) servo_.peak_torque_at_max_speed = servo_.torque_limit * (4.0 / 7.0);
  if (std::isnan(servo_.continuous_torque)) servo_.continuous_torque = servo_.torque_limit / 2.95;
  const ServoSpec& s = servo_;
  check_servo(s);
  check_load(load_);
  check_mechanism(mechanism_);
  // The legs' static forces (their deflection) are this rig's load's: the model carries it.
  if (const StaticLoadSpec load = static_load_spec(load_, mechanism_); !same_load(model_.spec().static_load, load)) {
    ModelSpec spec = model_.spec();
    spec.static_load = load;
    model_ = Model(spec);
  }
  substeps_ = check_simulation(simulation_);
  control_period_ = 1.0 / simulation_.control_rate;
  derive_drives();
}

void Rig::derive_drives() {
  const ServoSpec& s = servo_;
  for (int i = 0; i < kLegs; ++i) {
    const double lead = model_.leg(i).lead;
    if (!(lead > 0.0))
      throw Error(
          fmt::format("leg {}: lead: is {} m, but the drives (the servo section: motor speeds, torques, "
                      "gains) turn a screw: everything that uses them needs a lead screw on every leg (lead "
                      "> 0)",
                      i + 1, lead));
    motor_gain_[i] = lead / (2.0 * kPi * s.gear_ratio);
  }
  drive_inertia_ = s.motor_inertia + s.screw_inertia / (s.gear_ratio * s.gear_ratio);
  encoder_step_ = 2.0 * kPi / s.encoder_counts;

  // The inertia each motor sees at home: the diagonal of the whole mechanism's inertia in motor
  // angles (drive, leg bodies and the platform reflected through the legs; theory §9, §14).
  LegState home;
  detail::DriveLoad at_home;
  if (inverse_kinematics(model_, Placement{}, home) != Status::Ok ||
      detail::drive_load(*this, home, Vector6d::Zero(), Vector6d::Zero(), true, at_home) != Status::Ok)
    throw Error("legs: the platform Jacobian is singular at home; cannot size the servo");
  nominal_inertia_ = at_home.inverse_inertia.inverse().diagonal();

  if (s.kp == 0.0 && s.ki == 0.0 && s.kd == 0.0) {
    const double w = 2.0 * kPi * s.pole_frequency;
    if (w * control_period_ > kMaxBandwidthRatio)
      fail("servo.pole_frequency",
           fmt::format("{} Hz is too high for the control rate {} Hz (keep 2 pi pole_frequency / rate <= {})",
                       s.pole_frequency, simulation_.control_rate, kMaxBandwidthRatio));
    // J s^3 + (b + kd) s^2 + kp s + ki = J (s + w)^3: three closed-loop poles at -w (docs/theory.md §9).
    kp_ = 3.0 * w * w * nominal_inertia_;
    ki_ = w * w * w * nominal_inertia_;
    kd_ = (3.0 * w * nominal_inertia_.array() - s.viscous_friction).max(0.0).matrix();
  } else {
    kp_.setConstant(s.kp);
    ki_.setConstant(s.ki);
    kd_.setConstant(s.kd);
  }
}

}  // namespace hexatwist
