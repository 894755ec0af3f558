// SPDX-License-Identifier: BSD-3-Clause
// The closed loop on short trajectories: a settled start, the plant's length law (Eq. 10), the
// limit check before anything runs, and what each option changes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <iomanip>

#include "hexatwist/dynamics/dynamics.hpp"
#include "hexatwist/dynamics/mechanism.hpp"
#include "hexatwist/io/config.hpp"
#include "hexatwist/simulation/simulation.hpp"

namespace hexatwist {
namespace {

const Config& seed() {
  static const Config c = default_config();
  return c;
}

Trajectory still(const Pose& pose, double seconds) {
  Trajectory t;
  t.dt = seed().rig.control_period();
  t.poses.assign(static_cast<std::size_t>(seconds / t.dt) + 1, pose);
  return t;
}

TEST(Simulation, StartsSettledAndStaysPut) {
  Pose p;
  p.position = Vector3d(0.1, -0.05, 0.2);
  p.rpy = Vector3d(0.05, -0.1, 0.2);
  std::vector<SimulationSample> samples;
  SimulationIssue issue;
  ASSERT_EQ(simulate(seed().rig, still(p, 1.0), {}, samples, issue), Status::Ok);
  ASSERT_EQ(samples.size(), 1001u);
  double worst = 0.0;
  for (const SimulationSample& s : samples) worst = std::max(worst, s.error);
  // Held by the integrators from the first tick: only encoder-count dithering remains.
  EXPECT_LT(worst, 2e-8);  // measured ~4e-9 m
}

TEST(Simulation, PlantLengthIsMotorSideLengthPlusTheTwistTerm) {
  const Rig& rig = seed().rig;
  const Trajectory t =
      sweep_trajectory(5, deg2rad(10), {deg2rad(20), deg2rad(60), deg2rad(300)}, 0.05, rig.control_period());
  for (const bool twist_in_plant : {true, false}) {
    SimulationOptions o;
    o.twist_in_plant = twist_in_plant;
    std::vector<SimulationSample> samples;
    SimulationIssue issue;
    ASSERT_EQ(simulate(rig, t, o, samples, issue), Status::Ok);
    double worst = 0.0, largest_twist = 0.0;
    for (const SimulationSample& s : samples) {
      const Vector6d expected =
          twist_in_plant ? Vector6d(rig.model().geometry().twist_gain.cwiseProduct(s.twist)) : Vector6d::Zero();
      worst = std::max(worst, (s.length - s.motor - expected).cwiseAbs().maxCoeff());
      largest_twist = std::max(largest_twist, s.twist.cwiseAbs().maxCoeff());
      ASSERT_LE((s.encoder - s.motor).maxCoeff(), 1e-15);  // the encoder rounds down ...
      ASSERT_LT((s.motor - s.encoder).maxCoeff(), rig.motor_gain().maxCoeff() * rig.encoder_step() * 1.000001);
    }
    EXPECT_LT(worst, 1e-11);                // FK tolerance 1e-12 m
    EXPECT_GT(largest_twist, deg2rad(10));  // the legs really twisted (yaw 10 deg)
  }
}

TEST(Simulation, LengthOffsetsAreCommandedAwayAndPutBackByThePlant) {
  // Offsets shift every command by -delta and the plant's real length by +delta: the closed loop
  // does what it does without them (up to the encoder's rounding of other angles), in the
  // twisting plant and in the twist-free one.
  RigSpec spec{seed().rig.model().spec(), seed().rig.servo(), seed().rig.load(), seed().rig.simulation(),
               seed().rig.mechanism()};
  const std::array<double, kLegs> delta{1e-3, -0.7e-3, 0.2e-3, -1e-3, 0.5e-3, 0.0};
  for (std::size_t i = 0; i < delta.size(); ++i) spec.model.legs[i].length_offset = delta[i];
  const Rig offset(spec);
  const Rig& plain = seed().rig;
  const Trajectory t =
      sweep_trajectory(5, deg2rad(10), {deg2rad(20), deg2rad(60), deg2rad(300)}, 0.05, plain.control_period());
  for (const bool twist_in_plant : {true, false}) {
    SimulationOptions o;
    o.twist_in_plant = twist_in_plant;
    o.strategy = Strategy::Compensated;
    std::vector<SimulationSample> a, b;
    SimulationIssue issue;
    ASSERT_EQ(simulate(plain, t, o, a, issue), Status::Ok);
    ASSERT_EQ(simulate(offset, t, o, b, issue), Status::Ok);
    ASSERT_EQ(a.size(), b.size());
    double worst_error = 0.0, worst_law = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      worst_error = std::max(worst_error, std::abs(a[k].error - b[k].error));
      const Vector6d& gain = offset.model().geometry().twist_gain;
      const Vector6d twist_term = twist_in_plant ? Vector6d(gain.cwiseProduct(b[k].twist)) : Vector6d::Zero();
      const Vector6d law = b[k].length - b[k].motor - offset.model().geometry().length_offset - twist_term;
      worst_law = std::max(worst_law, law.cwiseAbs().maxCoeff());
    }
    // Measured 8.9e-9 m (about an encoder count, 9.5 nm) and 1e-12 m (the FK tolerance).
    EXPECT_LT(worst_error, 1e-7) << twist_in_plant;
    EXPECT_LT(worst_law, 1e-11) << twist_in_plant;
    std::printf("  twist in plant %d: error difference %.3g m, length law %.3g m\n", twist_in_plant, worst_error,
                worst_law);
  }
}

TEST(Simulation, CompensationRemovesTheTwistErrorExactly) {
  const Rig& rig = seed().rig;
  const Trajectory t = sweep_trajectory(2, 0.1, {0.2, 0.5, 2.5}, 0.05, rig.control_period());
  SimulationOptions o;
  std::vector<SimulationSample> comp, conv;
  SimulationIssue issue;
  ASSERT_EQ(simulate(rig, t, o, comp, issue), Status::Ok);
  o.strategy = Strategy::Conventional;
  ASSERT_EQ(simulate(rig, t, o, conv, issue), Status::Ok);
  double comp_twist = 0.0, conv_twist = 0.0;
  for (std::size_t k = 0; k < t.poses.size(); ++k) {
    comp_twist = std::max(comp_twist, comp[k].error_twist_only);
    conv_twist = std::max(conv_twist, conv[k].error_twist_only);
    // The compensated target differs from the conventional one by exactly the Eq. (10) term.
    ASSERT_LT((conv[k].command - comp[k].command).norm(), 2e-3);
  }
  EXPECT_LT(comp_twist, 1e-9);
  EXPECT_GT(conv_twist, 2e-5);
}

TEST(Simulation, NothingRunsOutsideALimit) {
  const Rig& rig = seed().rig;
  Trajectory t = sweep_trajectory(2, 0.8, {0.2, 0.5, 2.5}, 0.0, rig.control_period());  // z = +0.8 m: too long
  SimulationIssue issue;
  ASSERT_EQ(check_trajectory(rig, t, issue), Status::StrokeAboveMax);
  EXPECT_GE(issue.limit.leg, 0);
  EXPECT_GT(issue.limit.value, rig.model().spec().limits.length_max);
  EXPECT_NEAR(issue.time, t.time(issue.index), 1e-12);
  // The first sample past the limit, not any later one.
  CommandReport before;
  ASSERT_EQ(compute_commands(rig.model(), t.poses[issue.index - 1], before), Status::Ok);
  std::vector<SimulationSample> samples;
  SimulationIssue again;
  EXPECT_EQ(simulate(rig, t, {}, samples, again), Status::StrokeAboveMax);
  EXPECT_TRUE(samples.empty());
  EXPECT_EQ(again.index, issue.index);
}

TEST(Simulation, NothingRunsFasterThanTheMotors) {
  const Rig& rig = seed().rig;
  Trajectory t = still(Pose{}, 0.1);
  t.poses[50].position.z() = 0.01;  // a 10 mm jump in one tick: ~6000 rad/s at the motor
  SimulationIssue issue;
  ASSERT_EQ(check_trajectory(rig, t, issue), Status::MotorSpeedAboveMax);
  EXPECT_EQ(issue.index, 49u);  // the central difference at 49 sees the jump first
  EXPECT_GT(issue.limit.value, rig.servo().max_speed);
  EXPECT_EQ(issue.limit.bound, rig.servo().max_speed);
}

TEST(Simulation, AMotorSpeedOrHoldingTorqueOnItsLimitIsInsideAndPastItOutside) {
  // The limit put on the trajectory's own value, 1 ulp below it (inside the tolerance of
  // limits.hpp) and 1e-12 relative below it.
  const Rig& seed_rig = seed().rig;
  Trajectory t = still(Pose{}, 0.1);
  t.poses[50].position.z() = 0.01;
  SimulationIssue issue;
  ServoSpec fast = seed_rig.servo();
  fast.max_speed = 1e5;
  ASSERT_EQ(check_trajectory(Rig(seed_rig.model(), fast, seed_rig.load(), seed_rig.simulation()), t, issue),
            Status::Ok);
  ServoSpec at = seed_rig.servo();
  ASSERT_EQ(check_trajectory(seed_rig, t, issue), Status::MotorSpeedAboveMax);
  double speed = 0.0;  // the largest over the legs and ticks: raise the limit to each one reported
  for (double limit = issue.limit.value;; limit = issue.limit.value) {
    at.max_speed = limit;
    if (check_trajectory(Rig(seed_rig.model(), at, seed_rig.load(), seed_rig.simulation()), t, issue) == Status::Ok) {
      speed = limit;
      break;
    }
    ASSERT_EQ(issue.status, Status::MotorSpeedAboveMax);
  }
  for (const double bound : {speed, std::nextafter(speed, 0.0), speed * (1.0 - 1e-12)}) {
    at.max_speed = bound;
    const Status s = check_trajectory(Rig(seed_rig.model(), at, seed_rig.load(), seed_rig.simulation()), t, issue);
    EXPECT_EQ(s, bound == speed * (1.0 - 1e-12) ? Status::MotorSpeedAboveMax : Status::Ok)
        << std::setprecision(17) << bound;
  }
  ServoSpec weak;
  weak.torque_limit = 3.0;
  weak.peak_torque_at_max_speed = weak.continuous_torque = 2.0;
  ASSERT_EQ(check_trajectory(Rig(seed_rig.model(), weak, LoadSpec{}, SimulationSpec{}), still(Pose{}, 0.01), issue),
            Status::TorqueAboveMax);
  double hold = 0.0;  // the largest over the legs: the first leg reported may not hold the most
  for (double limit = issue.limit.value;; limit = issue.limit.value) {
    weak.torque_limit = limit;
    if (check_trajectory(Rig(seed_rig.model(), weak, LoadSpec{}, SimulationSpec{}), still(Pose{}, 0.01), issue) ==
        Status::Ok) {
      hold = limit;
      break;
    }
  }
  for (const double bound : {hold, std::nextafter(hold, 0.0), hold * (1.0 - 1e-12)}) {
    weak.torque_limit = bound;
    const Status s =
        check_trajectory(Rig(seed_rig.model(), weak, LoadSpec{}, SimulationSpec{}), still(Pose{}, 0.01), issue);
    EXPECT_EQ(s, bound == hold * (1.0 - 1e-12) ? Status::TorqueAboveMax : Status::Ok) << std::setprecision(17) << bound;
  }
}

TEST(Simulation, TheHoldingTorqueIsWhatTheTrajectoryCheckComparesWithTheLimit) {
  // The whole mechanism at rest (the inverse dynamics' gravity share), not the load alone: a limit
  // just above the largest holding torque passes a still trajectory, just below it does not.
  const Rig& rig = seed().rig;
  const Pose pose = Pose::from_vector((Vector6d() << 0.05, 0, 0.1, 0, 0.05, 0.2).finished());
  Vector6d hold;
  ASSERT_EQ(holding_torque(rig, pose, hold), Status::Ok);
  LegDynamics load_only;
  LegState legs;
  ASSERT_EQ(inverse_kinematics(rig.model(), pose, legs), Status::Ok);
  ASSERT_EQ(leg_dynamics(rig.model(), rig.load(), legs, LengthKind::Motor, load_only), Status::Ok);
  const double worst = hold.cwiseAbs().maxCoeff();
  EXPECT_GT(worst, rig.motor_gain().cwiseProduct(load_only.gravity).cwiseAbs().maxCoeff());  // the legs weigh too
  SimulationIssue issue;
  for (const double factor : {1.0 + 1e-9, 1.0 - 1e-9}) {
    ServoSpec servo = rig.servo();
    servo.torque_limit = worst * factor;
    servo.peak_torque_at_max_speed = servo.continuous_torque = 0.5 * servo.torque_limit;
    const Rig limited(rig.model(), servo, rig.load(), rig.simulation(), rig.mechanism());
    const Status s = check_trajectory(limited, still(pose, 0.01), issue);
    EXPECT_EQ(s, factor > 1.0 ? Status::Ok : Status::TorqueAboveMax);
    if (s == Status::TorqueAboveMax) {
      EXPECT_EQ(issue.limit.value, worst);
    }
  }
}

TEST(Simulation, NothingRunsIfAMotorCannotHoldTheLoad) {
  const Model& model = seed().rig.model();
  ServoSpec weak;
  weak.torque_limit = 3.0;  // the seed's load takes about 4.9 N m per motor at home
  weak.peak_torque_at_max_speed = weak.continuous_torque = 2.0;
  const Rig rig(model, weak, LoadSpec{}, SimulationSpec{});
  SimulationIssue issue;
  ASSERT_EQ(check_trajectory(rig, still(Pose{}, 0.01), issue), Status::TorqueAboveMax);
  EXPECT_EQ(issue.index, 0u);
  // The holding torque, from the potential energy of every body: J_phi^T tau = grad V.
  Vector6d grad;
  for (int j = 0; j < 6; ++j) {
    const double h = 1e-6;
    Placement plus, minus;
    if (j < 3) {
      plus.t[j] = h;
      minus.t[j] = -h;
    } else {
      plus.R_BP = exp_so3(h * Vector3d::Unit(j - 3));
      minus.R_BP = exp_so3(-h * Vector3d::Unit(j - 3));
    }
    double vp = 0, vm = 0;
    ASSERT_EQ(potential_energy(rig, plus, vp), Status::Ok);
    ASSERT_EQ(potential_energy(rig, minus, vm), Status::Ok);
    grad[j] = (vp - vm) / (2 * h);
  }
  LegState home;
  ASSERT_EQ(inverse_kinematics(model, Placement{}, home), Status::Ok);
  Matrix6d J;
  ASSERT_EQ(motor_jacobian(rig, home, J), Status::Ok);
  const Vector6d hold = J.transpose().lu().solve(grad);
  EXPECT_NEAR(issue.limit.value, std::abs(hold[issue.limit.leg]), 1e-6);  // the first leg over the limit
  EXPECT_GT(issue.limit.value, 5.0);  // 4.92 N m of them the platform's, the rest the legs'
  EXPECT_EQ(issue.limit.bound, 3.0);
}

TEST(Simulation, RefusesATrajectoryAtAnotherRate) {
  Trajectory t = still(Pose{}, 0.01);
  t.dt = 0.002;
  std::vector<SimulationSample> samples;
  SimulationIssue issue;
  EXPECT_NE(simulate(seed().rig, t, {}, samples, issue), Status::Ok);
  EXPECT_TRUE(samples.empty());
}

}  // namespace
}  // namespace hexatwist
