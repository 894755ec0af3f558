// SPDX-License-Identifier: BSD-3-Clause
// One drive under its PID: integrator against the exact solution, step response, torque limit,
// anti-windup and encoder quantisation. The six legs get a diagonal load here, so each behaves
// as a single axis.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>

#include "hexatwist/io/config.hpp"
#include "hexatwist/simulation/servo.hpp"

namespace hexatwist {
namespace {

Rig make_rig(const ServoSpec& servo) { return Rig(default_model(), servo, LoadSpec{}, SimulationSpec{}); }

// Runs `ticks` control periods towards a constant reference angle with a constant inertia per leg
// and no gravity; returns the angle history of leg 0 and the largest |torque| seen.
struct StepRun {
  std::vector<double> angle, measured, torque;
};
StepRun step(const Rig& rig, double target, int ticks, double inertia) {
  const Matrix6d inv = Matrix6d::Identity() / inertia;
  DriveState d;
  ControllerState c;
  Vector6d measured, torque;
  read_encoder(rig, d.angle, measured);
  start_controller(rig, measured, Vector6d::Zero(), c);
  ServoReference ref;
  ref.angle.setConstant(target);
  StepRun r;
  for (int k = 0; k < ticks; ++k) {
    read_encoder(rig, d.angle, measured);
    update_controller(rig, ref, measured, c, torque);
    r.angle.push_back(d.angle[0]);
    r.measured.push_back(measured[0]);
    r.torque.push_back(torque[0]);
    integrate_drives(rig, inv, Vector6d::Zero(), torque, d);
  }
  return r;
}

TEST(Servo, IntegratorMatchesTheExactSolution) {
  // J w' = tau - b w from rest: w(t) = tau/b (1 - exp(-b t / J)), theta = tau/b (t - J/b (1 - exp(-b t/J))).
  ServoSpec s;
  s.viscous_friction = 0.05;
  s.coulomb_friction = 0.0;
  s.torque_time_constant = 0.0;
  const Rig rig = make_rig(s);
  const double J = 2e-3, tau = 1.5, b = s.viscous_friction;
  DriveState d;
  const Matrix6d inv = Matrix6d::Identity() / J;
  const Vector6d torque = Vector6d::Constant(tau);
  double t = 0.0;
  for (int k = 0; k < 200; ++k) {
    integrate_drives(rig, inv, Vector6d::Zero(), torque, d);
    t += rig.control_period();
  }
  const double e = std::exp(-b * t / J);
  EXPECT_NEAR(d.speed[0], tau / b * (1 - e), 1e-9 * tau / b);
  EXPECT_NEAR(d.angle[0], tau / b * (t - J / b * (1 - e)), 1e-9 * tau / b * t);
}

TEST(Servo, TorqueLagsTheCommandByTheCurrentLoop) {
  ServoSpec s;
  s.torque_time_constant = 0.8e-3;
  const Rig rig = make_rig(s);
  DriveState d;
  const Matrix6d inv = Matrix6d::Identity() / 1e3;  // a huge inertia: only the torque matters here
  const Vector6d command = Vector6d::Constant(2.0);
  for (int k = 1; k <= 3; ++k) {
    integrate_drives(rig, inv, Vector6d::Zero(), command, d);
    const double t = k * rig.control_period();
    EXPECT_NEAR(d.torque[0], 2.0 * (1 - std::exp(-t / s.torque_time_constant)), 1e-5) << k;  // RK4, h/T = 1/8: 1.6e-6
  }
}

TEST(Servo, DryFrictionTakesItsShareOfTheTorque) {
  // Constant torque from rest: the speed settles where torque = b w + tc tanh(w / wf), i.e.
  // w = (torque - tc) / b once w >> wf; a torque below tc barely creeps.
  ServoSpec s;
  s.viscous_friction = 0.02;
  s.coulomb_friction = 0.4;
  s.torque_time_constant = 0.0;
  const Rig rig = make_rig(s);
  const Matrix6d inv = Matrix6d::Identity() / 2e-3;
  DriveState fast, slow;
  for (int k = 0; k < 2000; ++k) {
    integrate_drives(rig, inv, Vector6d::Zero(), Vector6d::Constant(1.0), fast);
    integrate_drives(rig, inv, Vector6d::Zero(), Vector6d::Constant(0.2), slow);
  }
  EXPECT_NEAR(fast.speed[0], (1.0 - 0.4) / 0.02, 1e-6 * 30.0);
  // Below tc: tanh(w / wf) = 0.2 / 0.4 exactly balances (b w is small): w = wf atanh(0.5) ~ 0.27 rad/s.
  EXPECT_LT(slow.speed[0], s.friction_speed);
  EXPECT_GT(slow.speed[0], 0.0);
}

TEST(Servo, StepResponseSettlesWithoutSteadyStateError) {
  ServoSpec linear;  // the controller alone: no dry friction, no current-loop lag
  linear.coulomb_friction = 0.0;
  linear.torque_time_constant = 0.0;
  const Rig rig = make_rig(linear);
  const double J = rig.nominal_inertia()[0];
  const double target = 0.1;  // rad, inside the torque limit
  const StepRun r = step(rig, target, 1500, J);
  // Three poles at -2 pi 10 rad/s: settled to 1% after 0.6 s, and no lasting error.
  for (std::size_t k = 600; k < r.angle.size(); ++k) ASSERT_NEAR(r.angle[k], target, 0.01 * target) << k;
  EXPECT_NEAR(r.angle.back(), target, 2 * rig.encoder_step());
  double peak = 0.0;
  for (const double a : r.angle) peak = std::max(peak, a);
  // With D on the measured speed the loop is (3 w^2 s + w^3) / (s + w)^3, whose step response
  // 1 - exp(-w t) (1 + w t - (w t)^2) peaks at 1 + 5 exp(-3) = 1.249 at w t = 3.
  EXPECT_NEAR(peak / target, 1.249, 0.04);  // measured 1.231: the 1 kHz sampled loop
}

TEST(Servo, TorqueNeverExceedsTheLimitAndTheIntegratorDoesNotWindUp) {
  ServoSpec spec;
  spec.torque_limit = 2.0;
  const Rig rig = make_rig(spec);
  const Matrix6d inv = Matrix6d::Identity() / rig.nominal_inertia()[0];
  DriveState d;
  ControllerState c;
  Vector6d measured, torque;
  read_encoder(rig, d.angle, measured);
  start_controller(rig, measured, Vector6d::Zero(), c);
  ServoReference ref;
  ref.angle.setConstant(0.5);  // rad: kp e is ~40 times the limit at first
  int at_limit = 0, frozen = 0;
  double peak = 0.0;
  double last_integral = c.integral[0];
  for (int k = 0; k < 3000; ++k) {
    read_encoder(rig, d.angle, measured);
    update_controller(rig, ref, measured, c, torque);
    ASSERT_LE(std::abs(torque[0]), spec.torque_limit);
    ASSERT_LE(std::abs(rig.ki()[0] * c.integral[0]), spec.torque_limit * (1 + 1e-12));
    if (std::abs(torque[0]) == spec.torque_limit) {
      ++at_limit;
      // Saturated and the error still pushing the same way: the integral must not grow.
      if ((ref.angle[0] - measured[0] > 0) == (torque[0] > 0)) {
        ASSERT_LE(std::abs(c.integral[0]), std::abs(last_integral) + 1e-15) << k;
        ++frozen;
      }
    }
    last_integral = c.integral[0];
    integrate_drives(rig, inv, Vector6d::Zero(), torque, d);
    peak = std::max(peak, d.angle[0]);
  }
  EXPECT_GT(at_limit, 20);  // measured 60
  EXPECT_GT(frozen, 20);
  EXPECT_LT(peak, 0.8);  // measured 0.715: the saturated approach overshoots, but settles
  EXPECT_NEAR(d.angle[0], 0.5, 1e-4);
}

TEST(Servo, EncoderQuantisationIsVisible) {
  ServoSpec s;
  s.encoder_counts = 1000;  // coarse, so that one count is a visible 6.3 mrad
  const Rig rig = make_rig(s);
  const double q = rig.encoder_step();
  EXPECT_NEAR(q, 2 * kPi / 1000, 1e-15);
  const StepRun r = step(rig, 0.1234, 1500, rig.nominal_inertia()[0]);
  for (std::size_t k = 0; k < r.angle.size(); ++k) {
    const double counts = r.measured[k] / q;
    ASSERT_NEAR(counts, std::round(counts), 1e-9);     // whole counts only
    ASSERT_LE(r.measured[k], r.angle[k] + 1e-15);      // rounded down ...
    ASSERT_GT(r.measured[k], r.angle[k] - q - 1e-15);  // ... by less than one count
  }
  // The loop can only hold the angle to about a count: the true angle keeps an error of the
  // order of the quantum that a finer encoder would not have.
  const Rig fine = make_rig(ServoSpec{});
  const StepRun rf = step(fine, 0.1234, 1500, fine.nominal_inertia()[0]);
  double coarse_err = 0.0, fine_err = 0.0;
  for (std::size_t k = 1000; k < 1500; ++k) {
    coarse_err = std::max(coarse_err, std::abs(r.angle[k] - 0.1234));
    fine_err = std::max(fine_err, std::abs(rf.angle[k] - 0.1234));
  }
  EXPECT_GT(coarse_err, 0.05 * q);
  EXPECT_LT(coarse_err, 3 * q);
  EXPECT_LT(fine_err, coarse_err / 20);
}

TEST(Servo, GainsComeFromTheBandwidth) {
  const Rig rig = make_rig(ServoSpec{});
  const double w = 2 * kPi * ServoSpec{}.pole_frequency;
  for (int i = 0; i < kLegs; ++i) {
    const double J = rig.nominal_inertia()[i];
    EXPECT_NEAR(rig.kp()[i], 3 * J * w * w, 1e-12 * rig.kp()[i]);
    EXPECT_NEAR(rig.ki()[i], J * w * w * w, 1e-12 * rig.ki()[i]);
  }
  ServoSpec given;
  given.kp = 100;
  given.ki = 2000;
  given.kd = 1;
  const Rig g = make_rig(given);
  EXPECT_EQ(g.kp()[3], 100);
  EXPECT_EQ(g.ki()[3], 2000);
  EXPECT_EQ(g.kd()[3], 1);
}

}  // namespace
}  // namespace hexatwist
