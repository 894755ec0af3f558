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

void positive(double v, const char* field, const char* unit) {
  if (!std::isfinite(v) || !(v > 0.0)) fail(field, fmt::format("expected > 0 {}, got {}", unit, v));
}

void non_negative(double v, const char* field, const char* unit) {
  if (!std::isfinite(v) || v < 0.0) fail(field, fmt::format("expected >= 0 {}, got {}", unit, v));
}

// Largest 2 pi pole_frequency / control rate for which the derived discrete loop keeps its margins.
constexpr double kMaxBandwidthRatio = 0.5;

}  // namespace

Rig::Rig(const RigSpec& spec) : Rig(Model(spec.model), spec.servo, spec.load, spec.simulation, spec.mechanism) {}

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
  positive(s.motor_inertia, "servo.motor_inertia", "kg m^2");
  non_negative(s.screw_inertia, "servo.screw_inertia", "kg m^2");
  non_negative(s.viscous_friction, "servo.viscous_friction", "N m s/rad");
  non_negative(s.coulomb_friction, "servo.coulomb_friction", "N m");
  positive(s.friction_speed, "servo.friction_speed", "rad/s");
  non_negative(s.torque_time_constant, "servo.torque_time_constant", "s");
  positive(s.torque_limit, "servo.torque_limit", "N m");
  positive(s.max_speed, "servo.max_speed", "rad/s");
  if (!std::isfinite(s.encoder_counts) || s.encoder_counts < 1.0 || s.encoder_counts != std::floor(s.encoder_counts))
    fail("servo.encoder_counts",
         fmt::format("expected a whole number >= 1 of counts per revolution, got {}", s.encoder_counts));
  positive(s.gear_ratio, "servo.gear_ratio", "motor revolutions per screw revolution");
  positive(s.pole_frequency, "servo.pole_frequency", "Hz");
  non_negative(s.kp, "servo.kp", "N m/rad");
  non_negative(s.ki, "servo.ki", "N m/(rad s)");
  non_negative(s.kd, "servo.kd", "N m s/rad");
  const bool derive = s.kp == 0.0 && s.ki == 0.0 && s.kd == 0.0;
  if (!derive && s.kp == 0.0)
    fail("servo.kp",
         "expected > 0 when ki or kd is given (or leave all three at 0 to derive them from servo.pole_frequency)");
  non_negative(s.velocity_feedforward, "servo.velocity_feedforward", "(fraction)");
  non_negative(s.acceleration_feedforward, "servo.acceleration_feedforward", "(fraction)");
  positive(s.peak_corner_speed, "servo.peak_corner_speed", "rad/s");
  if (s.peak_corner_speed > s.max_speed)
    fail("servo.peak_corner_speed",
         fmt::format("{} rad/s is above servo.max_speed ({} rad/s)", s.peak_corner_speed, s.max_speed));
  non_negative(s.peak_torque_at_max_speed, "servo.peak_torque_at_max_speed", "N m");
  if (s.peak_torque_at_max_speed > s.torque_limit)
    fail("servo.peak_torque_at_max_speed", fmt::format("{} N m is above the peak torque servo.torque_limit ({} N m)",
                                                       s.peak_torque_at_max_speed, s.torque_limit));
  positive(s.continuous_torque, "servo.continuous_torque", "N m");
  if (s.continuous_torque > s.torque_limit)
    fail("servo.continuous_torque", fmt::format("{} N m is above the peak torque servo.torque_limit ({} N m)",
                                                s.continuous_torque, s.torque_limit));

  positive(load_.mass, "load.mass", "kg");
  if (!load_.center_of_mass_P.allFinite()) fail("load.center_of_mass", "expected three finite numbers");
  for (int i = 0; i < 3; ++i) positive(load_.inertia[i], "load.inertia", "kg m^2 for each principal moment");
  non_negative(load_.gravity, "load.gravity", "m/s^2");
  if (!load_.products.allFinite()) fail("load.products_of_inertia", "expected three finite numbers");
  {
    // A physical inertia tensor is positive definite and its principal moments obey the triangle
    // inequality (each at most the sum of the other two).
    const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(load_.inertia_tensor(), Eigen::EigenvaluesOnly);
    const Vector3d l = eig.eigenvalues();
    if (!(l.minCoeff() > 0.0) || l[2] > (l[0] + l[1]) * (1.0 + 1e-12))
      fail("load.products_of_inertia",
           fmt::format("the inertia tensor has principal moments {:.6g}, {:.6g}, {:.6g} kg m^2: not a rigid body's "
                       "(each must be > 0 and at most the sum of the other two)",
                       l[0], l[1], l[2]));
  }
  const auto body = [](const LegBodySpec& b, const char* mass, const char* center, const char* axial,
                       const char* transverse) {
    non_negative(b.mass, mass, "kg");
    if (!std::isfinite(b.center)) fail(center, fmt::format("expected a finite distance [m], got {}", b.center));
    non_negative(b.axial_inertia, axial, "kg m^2");
    non_negative(b.transverse_inertia, transverse, "kg m^2");
  };
  body(mechanism_.housing, "mechanism.housing.mass", "mechanism.housing.center", "mechanism.housing.axial_inertia",
       "mechanism.housing.transverse_inertia");
  body(mechanism_.rod, "mechanism.rod.mass", "mechanism.rod.center", "mechanism.rod.axial_inertia",
       "mechanism.rod.transverse_inertia");
  for (const auto& [v, field] : {std::pair{mechanism_.efficiency, "mechanism.efficiency"},
                                 std::pair{mechanism_.back_efficiency, "mechanism.back_efficiency"}})
    if (!std::isfinite(v) || !(v > 0.0) || v > 1.0)
      fail(field, fmt::format("expected a fraction in (0, 1], got {}", v));

  positive(simulation_.control_rate, "simulation.control_rate", "Hz");
  positive(simulation_.plant_step, "simulation.plant_step", "s");
  control_period_ = 1.0 / simulation_.control_rate;
  if (simulation_.plant_step > control_period_ * (1.0 + 1e-12))
    fail("simulation.plant_step",
         fmt::format("{} s is longer than the control period {} s", simulation_.plant_step, control_period_));
  // Counted in double and checked before the conversion: a tiny step (1e-40 s) would overflow an int.
  const double substeps = std::ceil(control_period_ / simulation_.plant_step * (1.0 - 1e-12));
  if (!(substeps <= 10000.0))
    fail("simulation.plant_step",
         fmt::format("{} s gives more than 10000 steps per control period", simulation_.plant_step));
  substeps_ = static_cast<int>(substeps);

  for (int i = 0; i < kLegs; ++i) {
    const double lead = model_.leg(i).lead;
    if (!(lead > 0.0))
      throw Error(fmt::format("leg {}: lead: the servo simulation needs a lead screw on every leg (lead > 0)", i + 1));
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

  if (derive) {
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
