// SPDX-License-Identifier: BSD-3-Clause
// Dynamics of the whole mechanism, checked without its own derivation: the mass matrix against the
// kinetic energy (a quadratic form in the velocity), the inverse dynamics against Lagrange's
// equations by finite differences of the energies, the reduced model against the leg-space load,
// energy conservation of the forward dynamics, and forward against inverse dynamics.
#include <gtest/gtest.h>

#include <cmath>

#include "dynamics/mechanism_internal.hpp"
#include "hexatwist/dynamics/dynamics.hpp"
#include "hexatwist/dynamics/mechanism.hpp"
#include "hexatwist/io/config.hpp"
#include "hexatwist/kinematics/twist.hpp"
#include "support.hpp"

namespace hexatwist {
namespace {
using namespace test;

RigSpec seed_rig_spec() { return parse_config_spec(seed_config_yaml(), "seed.yaml").rig; }

// The seed rig without friction and with ideal screws (energy is conserved).
RigSpec frictionless_spec() {
  RigSpec spec = seed_rig_spec();
  spec.servo.viscous_friction = 0.0;
  spec.servo.coulomb_friction = 0.0;
  spec.mechanism.efficiency = spec.mechanism.back_efficiency = 1.0;
  return spec;
}

// A load whose centre of mass is off the axis and whose tensor is not diagonal, so that every
// term of the platform's dynamics is exercised; heavier rods so the legs' terms are too.
RigSpec rich_spec() {
  RigSpec spec = frictionless_spec();
  spec.load.center_of_mass_P = Vector3d(0.12, -0.08, 0.2);
  spec.load.inertia = Vector3d(600.0, 560.0, 1000.0);
  spec.load.products = Vector3d(20.0, -35.0, 15.0);
  spec.mechanism.rod.axial_inertia = 0.4;
  spec.mechanism.housing.axial_inertia = 0.7;
  return spec;
}

Matrix3d skew(const Vector3d& v) {
  Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

// Left Jacobian of SO(3): for R = exp(r) R0, the angular velocity [B] is w = J(r) r'.
Matrix3d left_jacobian(const Vector3d& r) {
  const double a = r.norm();
  const Matrix3d K = skew(r);
  if (a < 1e-8) return Matrix3d::Identity() + 0.5 * K;
  return Matrix3d::Identity() + (1.0 - std::cos(a)) / (a * a) * K + (a - std::sin(a)) / (a * a * a) * K * K;
}

Vector6d random_vector(std::mt19937_64& rng, double lin, double ang) {
  Vector6d v;
  for (int k = 0; k < 3; ++k) v[k] = uniform(rng, -lin, lin);
  for (int k = 3; k < 6; ++k) v[k] = uniform(rng, -ang, ang);
  return v;
}

double kinetic(const Rig& rig, const Placement& x, const Vector6d& v) {
  double T = 0.0;
  EXPECT_EQ(kinetic_energy(rig, x, v, T), Status::Ok);
  return T;
}

double potential(const Rig& rig, const Placement& x) {
  double V = 0.0;
  EXPECT_EQ(potential_energy(rig, x, V), Status::Ok);
  return V;
}

TEST(Mechanism, MotorJacobianIsTheMotorSideLengthJacobianOverTheMotorGain) {
  const Rig rig(seed_rig_spec());
  std::mt19937_64 rng(kSeed);
  double worst = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const Pose pose = random_valid_pose(rig.model(), rng, 0.4, deg2rad(25));
    LegState legs;
    ASSERT_EQ(inverse_kinematics(rig.model(), pose, legs), Status::Ok);
    Matrix6d J_phi, J_m;
    ASSERT_EQ(motor_jacobian(rig, legs, J_phi), Status::Ok);
    ASSERT_EQ(length_jacobian(rig.model(), legs, LengthKind::Motor, J_m), Status::Ok);
    const Matrix6d expected = rig.motor_gain().cwiseInverse().asDiagonal() * J_m;
    worst = std::max(worst, (J_phi - expected).cwiseAbs().maxCoeff() / expected.cwiseAbs().maxCoeff());
  }
  report("relative difference of J_phi", worst);
  EXPECT_LT(worst, 1e-12);
}

TEST(Mechanism, MotorAnglesIntegrateTheMotorSpeed) {
  // phi(x(t)) differentiated along a motion equals the speed inverse dynamics reports.
  const Rig rig(seed_rig_spec());
  std::mt19937_64 rng(kSeed + 1);
  double worst = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = random_valid_pose(rig.model(), rng, 0.3, deg2rad(20));
    const Vector6d rate = random_vector(rng, 0.5, 1.0);
    PlatformMotion motion = platform_motion(pose, rate, Vector6d::Zero());
    InverseDynamics id;
    ASSERT_EQ(inverse_dynamics(rig, motion, id), Status::Ok);
    const double h = 1e-6;
    Vector6d ap, am;
    ASSERT_EQ(motor_angles(rig, placement_from_pose(Pose::from_vector(pose.to_vector() + h * rate)), ap), Status::Ok);
    ASSERT_EQ(motor_angles(rig, placement_from_pose(Pose::from_vector(pose.to_vector() - h * rate)), am), Status::Ok);
    const Vector6d fd = (ap - am) / (2.0 * h);
    worst = std::max(worst, (fd - id.speed).cwiseAbs().maxCoeff() / id.speed.cwiseAbs().maxCoeff());
  }
  report("relative difference of the motor speed", worst);
  EXPECT_LT(worst, 1e-7);
}

TEST(Mechanism, PlatformMotionMatchesTheRotationsDerivatives) {
  std::mt19937_64 rng(kSeed + 2);
  double worst_w = 0.0, worst_wd = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = random_pose(rng, 0.2, deg2rad(40));
    const Vector6d rate = random_vector(rng, 0.5, 1.5), acc = random_vector(rng, 2.0, 4.0);
    const auto at = [&](double t) { return Pose::from_vector(pose.to_vector() + t * rate + 0.5 * t * t * acc); };
    const auto omega = [&](double t) {
      const double h = 1e-6;
      const Matrix3d Rp = rotation_from_rpy(at(t + h).rpy), Rm = rotation_from_rpy(at(t - h).rpy);
      const Matrix3d W = (Rp - Rm) / (2.0 * h) * rotation_from_rpy(at(t).rpy).transpose();
      return Vector3d(W(2, 1), W(0, 2), W(1, 0));
    };
    const PlatformMotion m = platform_motion(pose, rate, acc);
    worst_w = std::max(worst_w, (m.velocity.tail<3>() - omega(0.0)).norm());
    const double h = 1e-4;
    worst_wd = std::max(worst_wd, (m.acceleration.tail<3>() - (omega(h) - omega(-h)) / (2.0 * h)).norm());
    EXPECT_EQ(m.velocity.head<3>(), rate.head<3>());
  }
  report("|w - finite difference| [rad/s]", worst_w);
  report("|w' - finite difference| [rad/s^2]", worst_wd);
  EXPECT_LT(worst_w, 1e-8);
  EXPECT_LT(worst_wd, 1e-5);
}

TEST(Mechanism, MassMatrixIsTheHessianOfTheKineticEnergy) {
  // T is a quadratic form in the velocity: M_ii = 2 T(e_i), M_ij = T(e_i + e_j) - T(e_i) - T(e_j).
  const Rig rig(rich_spec());
  std::mt19937_64 rng(kSeed + 3);
  double worst = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const Placement x = placement_from_pose(random_valid_pose(rig.model(), rng, 0.4, deg2rad(25)));
    Matrix6d M;
    ASSERT_EQ(mechanism_mass_matrix(rig, x, M), Status::Ok);
    Matrix6d H;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        const Vector6d ei = Vector6d::Unit(i), ej = Vector6d::Unit(j);
        H(i, j) =
            i == j ? 2.0 * kinetic(rig, x, ei) : kinetic(rig, x, ei + ej) - kinetic(rig, x, ei) - kinetic(rig, x, ej);
      }
    worst = std::max(worst, (M - H).cwiseAbs().maxCoeff() / H.cwiseAbs().maxCoeff());
  }
  report("relative difference of M and the Hessian of T", worst);
  EXPECT_LT(worst, 1e-11);
}

// Lagrange's equations by finite differences, in coordinates q = (t, r) with R = exp(r) R0 about
// the current pose (at r = 0: r' = w, r'' = w', and the force on r is the torque):
//   Q = d/dt dT/dq' - dT/dq + dV/dq.
Vector6d lagrange_force(const Rig& rig, const Placement& x0, const Vector6d& qd, const Vector6d& qdd) {
  const auto T = [&](const Vector6d& q, const Vector6d& qdot) {
    Placement x;
    x.t = x0.t + q.head<3>();
    x.R_BP = exp_so3(q.tail<3>()) * x0.R_BP;
    Vector6d v;
    v.head<3>() = qdot.head<3>();
    v.tail<3>() = left_jacobian(q.tail<3>()) * qdot.tail<3>();
    return kinetic(rig, x, v);
  };
  const auto V = [&](const Vector6d& q) {
    Placement x;
    x.t = x0.t + q.head<3>();
    x.R_BP = exp_so3(q.tail<3>()) * x0.R_BP;
    return potential(rig, x);
  };
  // dT/dq' is exact by central differences (T is quadratic in q').
  const auto momentum = [&](const Vector6d& q, const Vector6d& qdot) {
    Vector6d p;
    for (int i = 0; i < 6; ++i) {
      const double e = 1.0;
      const Vector6d d = e * Vector6d::Unit(i);
      p[i] = (T(q, qdot + d) - T(q, qdot - d)) / (2.0 * e);
    }
    return p;
  };
  const double ht = 1e-4;
  const auto q_at = [&](double t) { return Vector6d(qd * t + 0.5 * qdd * t * t); };
  const auto qd_at = [&](double t) { return Vector6d(qd + qdd * t); };
  // Fourth-order central differences in time and in q.
  const Vector6d pdot = (-momentum(q_at(2 * ht), qd_at(2 * ht)) + 8.0 * momentum(q_at(ht), qd_at(ht)) -
                         8.0 * momentum(q_at(-ht), qd_at(-ht)) + momentum(q_at(-2 * ht), qd_at(-2 * ht))) /
                        (12.0 * ht);
  Vector6d dTdq, dVdq;
  const double hq = 1e-4;
  for (int i = 0; i < 6; ++i) {
    const Vector6d d = hq * Vector6d::Unit(i);
    const Vector6d z = Vector6d::Zero();
    dTdq[i] = (-T(z + 2 * d, qd) + 8.0 * T(z + d, qd) - 8.0 * T(z - d, qd) + T(z - 2 * d, qd)) / (12.0 * hq);
    dVdq[i] = (-V(z + 2 * d) + 8.0 * V(z + d) - 8.0 * V(z - d) + V(z - 2 * d)) / (12.0 * hq);
  }
  return pdot - dTdq + dVdq;
}

TEST(Mechanism, InverseDynamicsSatisfiesLagrangesEquations) {
  const Rig rig(rich_spec());
  std::mt19937_64 rng(kSeed + 4);
  double worst = 0.0;
  for (int trial = 0; trial < 12; ++trial) {
    PlatformMotion motion;
    motion.placement = placement_from_pose(random_valid_pose(rig.model(), rng, 0.4, deg2rad(25)));
    motion.velocity = random_vector(rng, 1.0, 1.5);
    motion.acceleration = random_vector(rng, 5.0, 8.0);
    InverseDynamics id;
    ASSERT_EQ(inverse_dynamics(rig, motion, id), Status::Ok);
    Matrix6d J;
    ASSERT_EQ(motor_jacobian(rig, id.legs_state, J), Status::Ok);
    const Vector6d Q_id = J.transpose() * id.torque;
    const Vector6d Q_fd = lagrange_force(rig, motion.placement, motion.velocity, motion.acceleration);
    worst = std::max(worst, (Q_id - Q_fd).cwiseAbs().maxCoeff() / Q_fd.cwiseAbs().maxCoeff());
  }
  report("relative difference of J^T tau and Lagrange's generalised force", worst);
  EXPECT_LT(worst, 1e-8);
}

TEST(Mechanism, VelocityProductTermsAreLagrangesAtZeroAccelerationWithoutGravity) {
  RigSpec spec = rich_spec();
  spec.load.gravity = 0.0;
  const Rig rig(spec);
  std::mt19937_64 rng(kSeed + 5);
  double worst = 0.0;
  for (int trial = 0; trial < 8; ++trial) {
    const Placement x = placement_from_pose(random_valid_pose(rig.model(), rng, 0.4, deg2rad(25)));
    const Vector6d v = random_vector(rng, 1.0, 1.5);
    Vector6d bias;
    ASSERT_EQ(mechanism_bias(rig, x, v, bias), Status::Ok);
    const Vector6d Q_fd = lagrange_force(rig, x, v, Vector6d::Zero());
    worst = std::max(worst, (bias - Q_fd).cwiseAbs().maxCoeff() / Q_fd.cwiseAbs().maxCoeff());
  }
  report("relative difference of the velocity-product terms", worst);
  EXPECT_LT(worst, 3e-8);
}

TEST(Mechanism, WithMasslessLegsAndNoRotorItIsTheLegSpaceLoad) {
  RigSpec spec = frictionless_spec();
  spec.mechanism.housing = spec.mechanism.rod = LegBodySpec{};
  spec.servo.motor_inertia = 1e-300;  // the rig needs a rotor; this one adds nothing
  spec.servo.screw_inertia = 0.0;
  const Rig rig(spec);
  std::mt19937_64 rng(kSeed + 6);
  double worst_mass = 0.0, worst_gravity = 0.0;
  for (int trial = 0; trial < 30; ++trial) {
    const Placement x = placement_from_pose(random_valid_pose(rig.model(), rng, 0.4, deg2rad(25)));
    LegState legs;
    ASSERT_EQ(inverse_kinematics(rig.model(), x, legs), Status::Ok);
    LegDynamics reduced;
    ASSERT_EQ(leg_dynamics(rig.model(), rig.load(), legs, LengthKind::Motor, reduced), Status::Ok);
    Matrix6d M, J;
    ASSERT_EQ(mechanism_mass_matrix(rig, x, M), Status::Ok);
    ASSERT_EQ(motor_jacobian(rig, legs, J), Status::Ok);
    // In motor angles: J^-T M J^-1 = C M_m C, with m = C phi.
    const Matrix6d Jinv = J.inverse();
    const Matrix6d A = Jinv.transpose() * M * Jinv;
    const Matrix6d expected = rig.motor_gain().asDiagonal() * reduced.mass * rig.motor_gain().asDiagonal();
    worst_mass = std::max(worst_mass, (A - expected).cwiseAbs().maxCoeff() / expected.cwiseAbs().maxCoeff());
    PlatformMotion still;
    still.placement = x;
    InverseDynamics id;
    ASSERT_EQ(inverse_dynamics(rig, still, id), Status::Ok);
    const Vector6d hold = -rig.motor_gain().cwiseProduct(reduced.gravity);
    worst_gravity = std::max(worst_gravity, (id.torque - hold).cwiseAbs().maxCoeff() / hold.cwiseAbs().maxCoeff());
  }
  report("relative difference of the motor-space mass matrix", worst_mass);
  report("relative difference of the holding torque", worst_gravity);
  EXPECT_LT(worst_mass, 1e-11);
  EXPECT_LT(worst_gravity, 1e-11);
}

TEST(Mechanism, ForwardDynamicsInvertsInverseDynamics) {
  const Rig rig(rich_spec());
  std::mt19937_64 rng(kSeed + 7);
  double worst = 0.0;
  for (int trial = 0; trial < 30; ++trial) {
    PlatformMotion motion;
    motion.placement = placement_from_pose(random_valid_pose(rig.model(), rng, 0.4, deg2rad(25)));
    motion.velocity = random_vector(rng, 1.0, 1.5);
    motion.acceleration = random_vector(rng, 5.0, 8.0);
    InverseDynamics id;
    ASSERT_EQ(inverse_dynamics(rig, motion, id), Status::Ok);
    Vector6d acc;
    ASSERT_EQ(forward_dynamics(rig, motion.placement, motion.velocity, id.torque, acc), Status::Ok);
    worst =
        std::max(worst, (acc - motion.acceleration).cwiseAbs().maxCoeff() / motion.acceleration.cwiseAbs().maxCoeff());
  }
  report("relative difference of the acceleration", worst);
  EXPECT_LT(worst, 1e-10);
}

TEST(Mechanism, ShareOfGravityIsTheHoldingTorqueAndFrictionVanishesWithoutIt) {
  // The seed rig (with friction): the torque is the frictionless rig's plus friction; gravity's
  // share equals the frictionless holding torque.
  const Rig with(seed_rig_spec()), without(frictionless_spec());
  std::mt19937_64 rng(kSeed + 8);
  int checked = 0;
  for (int trial = 0; trial < 10; ++trial) {
    PlatformMotion motion;
    motion.placement = placement_from_pose(random_valid_pose(with.model(), rng, 0.3, deg2rad(20)));
    motion.velocity = random_vector(rng, 0.5, 0.8);
    motion.acceleration = random_vector(rng, 3.0, 5.0);
    InverseDynamics a, b;
    ASSERT_EQ(inverse_dynamics(with, motion, a), Status::Ok);
    ASSERT_EQ(inverse_dynamics(without, motion, b), Status::Ok);
    EXPECT_LT((b.friction).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT(b.thread_dissipation.cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((a.torque - a.friction - b.torque).cwiseAbs().maxCoeff(), 1e-9 * b.torque.cwiseAbs().maxCoeff());
    // Efficiency: where the nut slides fast (the smoothing spent), the thread's loss is the ideal
    // torque times 1/eta - 1 where the power through the thread is positive (the screw drives the
    // load), times 1 - eta' where it is negative. The ideal torque is the frictionless rig's less its
    // drives' share; the loss pair is the thread's dissipation over its speed.
    for (int i = 0; i < kLegs; ++i) {
      const double screw = b.torque[i] - b.drives[i];
      const double w = a.thread_speed[i];
      if (std::abs(w) < 20.0 * with.servo().friction_speed) continue;
      const double pair = a.thread_dissipation[i] / w;
      const double expected =
          (screw * w > 0.0 ? 1.0 / with.mechanism().efficiency - 1.0 : with.mechanism().back_efficiency - 1.0) * screw;
      EXPECT_NEAR(pair, expected, 1e-9 * std::abs(screw)) << "leg " << i + 1;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
}

// The energy rate along a motion through pose p0 with constant pose acceleration, by a five-point
// central difference of kinetic plus potential energy.
double energy_rate(const Rig& rig, const Pose& p0, const Vector6d& rate, const Vector6d& acc) {
  const auto energy = [&](double t) {
    const Vector6d q = p0.to_vector() + t * rate + 0.5 * t * t * acc;
    const PlatformMotion m = platform_motion(Pose::from_vector(q), rate + t * acc, acc);
    return kinetic(rig, m.placement, m.velocity) + potential(rig, m.placement);
  };
  const double h = 1e-3;
  return (-energy(2 * h) + 8 * energy(h) - 8 * energy(-h) + energy(-2 * h)) / (12 * h);
}

TEST(Mechanism, MotorPowerIsTheEnergyRatePlusEveryLossAtEveryInstant) {
  // On random motions of the seed rig and of a rig with an off-axis load and heavier rods (both
  // with friction and screw efficiencies), slow ones near a motor's reversal included: the motors'
  // power sum_i tau_i phi'_i is the rate of kinetic plus potential energy (finite differences of
  // the energies, independent of the Newton-Euler projection) plus what the bearings dissipate
  // (drive_friction * speed) plus what the threads dissipate, and no thread ever gives energy back.
  RigSpec rich = rich_spec();
  const RigSpec seed = seed_rig_spec();
  rich.servo = seed.servo;
  rich.mechanism.efficiency = seed.mechanism.efficiency;
  rich.mechanism.back_efficiency = seed.mechanism.back_efficiency;
  const Rig rigs[] = {Rig(seed), Rig(rich)};
  std::mt19937_64 rng(kSeed + 12);
  double worst = 0.0, dissipated = 0.0;
  for (const Rig& rig : rigs) {
    for (int trial = 0; trial < 60; ++trial) {
      const Pose p0 = random_valid_pose(rig.model(), rng, 0.3, deg2rad(20));
      const double scale = trial % 3 == 0 ? 1e-3 : 1.0;  // every third: slow, around the reversals
      const Vector6d rate = scale * random_vector(rng, 0.5, 0.8), acc = random_vector(rng, 3.0, 5.0);
      InverseDynamics id;
      ASSERT_EQ(inverse_dynamics(rig, platform_motion(p0, rate, acc), id), Status::Ok);
      const double motors = id.power.sum();
      const double bearings = drive_friction(rig, id.speed).dot(id.speed);
      const double threads = id.thread_dissipation.sum();
      const double rate_of_energy = energy_rate(rig, p0, rate, acc);
      const double size = std::abs(motors) + std::abs(rate_of_energy) + bearings + threads;
      worst = std::max(worst, std::abs(motors - (rate_of_energy + bearings + threads)) / size);
      EXPECT_GE(id.thread_dissipation.minCoeff(), 0.0) << str(p0);
      dissipated = std::max(dissipated, threads / size);
    }
  }
  // The residual is the finite difference's rounding: 1e-15 of the energy (kJ) over its step.
  report("power balance, relative to the powers' sizes", worst);
  EXPECT_LT(worst, 3e-8);
  EXPECT_GT(dissipated, 0.01);  // the threads' share is far above the tolerance
}

TEST(Mechanism, TheThreadsLossFollowsTheNutNotTheMotor) {
  // Issue 23's example: the seed at home, yawing at 0.5 rad/s with the heave that stops motor 1.
  // Its nut still slides (the leg twists) at 1.32 mm/s under 3.3 kN of compression: the screw
  // drives the load, so the thread loses 1/eta - 1 of the power through it, and motor 1 holds
  // 6.17 N m, where a loss decided by the motor's speed alone gave 5.40.
  const Rig rig(seed_rig_spec()), ideal(frictionless_spec());
  const auto motion = [](double heave) {
    Vector6d rate = Vector6d::Zero();
    rate[2] = heave;
    rate[5] = 0.5;
    return platform_motion(Pose{}, rate, Vector6d::Zero());
  };
  InverseDynamics a, b;
  ASSERT_EQ(inverse_dynamics(rig, motion(0.0), a), Status::Ok);
  ASSERT_EQ(inverse_dynamics(rig, motion(1.0), b), Status::Ok);
  const double heave = -a.speed[0] / (b.speed[0] - a.speed[0]);  // the speeds are linear in the heave
  EXPECT_NEAR(heave, 0.4586, 1e-4);
  InverseDynamics id, free;
  ASSERT_EQ(inverse_dynamics(rig, motion(heave), id), Status::Ok);
  ASSERT_EQ(inverse_dynamics(ideal, motion(heave), free), Status::Ok);
  EXPECT_LT(std::abs(id.speed[0]), 1e-12);
  // The nut's speed from the length's own rate (a central difference of inverse kinematics).
  const auto length = [&](double t) {
    LegState legs;
    Pose p;
    p.position.z() = heave * t;
    p.rpy.z() = 0.5 * t;
    EXPECT_EQ(inverse_kinematics(rig.model(), p, legs), Status::Ok);
    return legs.length[0];
  };
  const double length_rate = (length(1e-6) - length(-1e-6)) / 2e-6;
  EXPECT_NEAR(length_rate, 1.316e-3, 1e-6);
  EXPECT_NEAR(id.thread_speed[0], length_rate / rig.motor_gain()[0], 1e-6);
  EXPECT_NEAR(id.screw_force[0], -3308.0, 1.0);
  // Motor 1 does no work; its thread dissipates 1/eta - 1 of the power through it (smoothed).
  const double screw = free.torque[0] - free.drives[0];
  const double w = id.thread_speed[0];
  const double expected =
      (1.0 / rig.mechanism().efficiency - 1.0) * screw * w * std::tanh(w / rig.servo().friction_speed);
  EXPECT_NEAR(id.thread_dissipation[0], expected, 1e-9);
  std::printf("  motor 1: %.4f N m (frictionless %.4f); thread at %.3f mm/s dissipates %.3f W\n", id.torque[0],
              free.torque[0], 1e3 * length_rate, id.thread_dissipation[0]);
  EXPECT_NEAR(id.torque[0], 6.17, 0.005);
}

TEST(Mechanism, TheClosedLoopsDriveEquationGivesTheInverseDynamicsTorque) {
  // The closed-loop simulation integrates A phi'' = tau - drive_friction - thread_loss + L
  // (detail::drive_load, theory §14): at the state, speeds and acceleration of an inverse-dynamics
  // motion, solving it for tau gives the inverse dynamics' torque, the threads' losses included,
  // and its thread loss is the inverse dynamics' friction less the bearings'.
  const Rig rig(seed_rig_spec());
  std::mt19937_64 rng(kSeed + 13);
  double worst = 0.0;
  for (int trial = 0; trial < 30; ++trial) {
    const Pose p0 = random_valid_pose(rig.model(), rng, 0.3, deg2rad(20));
    const double scale = trial % 2 == 0 ? 1e-3 : 1.0;
    const PlatformMotion motion =
        platform_motion(p0, scale * random_vector(rng, 0.5, 0.8), random_vector(rng, 3.0, 5.0));
    InverseDynamics id;
    ASSERT_EQ(inverse_dynamics(rig, motion, id), Status::Ok);
    detail::DriveLoad load;
    ASSERT_EQ(detail::drive_load(rig, id.legs_state, id.speed, id.acceleration, true, load), Status::Ok);
    const Vector6d tau =
        load.inverse_inertia.inverse() * id.acceleration + drive_friction(rig, id.speed) + load.thread_loss - load.load;
    const double size = id.torque.cwiseAbs().maxCoeff();
    worst = std::max(worst, (tau - id.torque).cwiseAbs().maxCoeff() / size);
    worst = std::max(worst,
                     (load.thread_loss - (id.friction - drive_friction(rig, id.speed))).cwiseAbs().maxCoeff() / size);
  }
  report("relative difference of the drive equation's torque and thread loss", worst);
  EXPECT_LT(worst, 1e-12);
}

// The platform state for integration: placement and velocity.
struct State {
  Placement x;
  Vector6d v;
};

// One classical RK4 step of the unpowered mechanism in coordinates (t, r) about the step's start.
State rk4_step(const Rig& rig, const State& s, double h) {
  const auto f = [&](const Vector6d& q, const Vector6d& v, Vector6d& qdot, Vector6d& vdot) {
    Placement x;
    x.t = s.x.t + q.head<3>();
    x.R_BP = exp_so3(q.tail<3>()) * s.x.R_BP;
    qdot.head<3>() = v.head<3>();
    qdot.tail<3>() = left_jacobian(q.tail<3>()).inverse() * v.tail<3>();
    EXPECT_EQ(forward_dynamics(rig, x, v, Vector6d::Zero(), vdot), Status::Ok);
  };
  const Vector6d q0 = Vector6d::Zero();
  Vector6d k1q, k1v, k2q, k2v, k3q, k3v, k4q, k4v;
  f(q0, s.v, k1q, k1v);
  f(q0 + 0.5 * h * k1q, s.v + 0.5 * h * k1v, k2q, k2v);
  f(q0 + 0.5 * h * k2q, s.v + 0.5 * h * k2v, k3q, k3v);
  f(q0 + h * k3q, s.v + h * k3v, k4q, k4v);
  const Vector6d q = (h / 6.0) * (k1q + 2 * k2q + 2 * k3q + k4q);
  State out;
  out.x.t = s.x.t + q.head<3>();
  out.x.R_BP = exp_so3(q.tail<3>()) * s.x.R_BP;
  out.v = s.v + (h / 6.0) * (k1v + 2 * k2v + 2 * k3v + k4v);
  return out;
}

TEST(Mechanism, UnpoweredMotionConservesEnergyOverTenSeconds) {
  // Motors unpowered, gravity on, no friction: the platform sinks and tumbles slowly under its
  // own weight (a flywheel-sized rotor keeps it in the workspace for 10 s), and T + V is constant.
  RigSpec spec = rich_spec();
  spec.servo.motor_inertia = 2.0;
  const Rig rig(spec);
  State s;
  s.v << 0.01, -0.008, 0.025, 0.01, -0.012, 0.03;
  const double e0 = kinetic(rig, s.x, s.v) + potential(rig, s.x);
  double worst = 0.0, t_max = 0.0, scale = 0.0;
  const double h = 5e-3;
  for (int k = 0; k < 2000; ++k) {
    s = rk4_step(rig, s, h);
    const double T = kinetic(rig, s.x, s.v), V = potential(rig, s.x);
    scale = std::max({scale, T, std::abs(V)});
    worst = std::max(worst, std::abs(T + V - e0));
    t_max = std::max(t_max, s.x.t.norm());
  }
  report("largest |x| during the run [m]", t_max);
  report("relative energy drift over 10 s", worst / scale);
  CommandReport inside;
  EXPECT_EQ(compute_commands(rig.model(), pose_from_placement(s.x), inside), Status::Ok) << "left the workspace";
  EXPECT_GT(t_max, 0.05);  // it did move
  EXPECT_LT(worst / scale, 1e-8);
}

TEST(Mechanism, PeakTorqueEnvelope) {
  const ServoSpec sv = Rig(seed_rig_spec()).servo();
  EXPECT_EQ(peak_torque_at(sv, 0.0), sv.torque_limit);
  EXPECT_EQ(peak_torque_at(sv, -sv.peak_corner_speed), sv.torque_limit);
  EXPECT_NEAR(peak_torque_at(sv, sv.max_speed), sv.peak_torque_at_max_speed, 1e-12);
  EXPECT_NEAR(peak_torque_at(sv, 0.5 * (sv.max_speed + sv.peak_corner_speed)),
              0.5 * (sv.torque_limit + sv.peak_torque_at_max_speed), 1e-12);
  EXPECT_EQ(peak_torque_at(sv, sv.max_speed * 1.0001), 0.0);
  EXPECT_EQ(peak_torque_at(sv, std::nan("")), 0.0);
  // Not given: derived from the peak torque and speed (the seed's numbers).
  RigSpec spec = seed_rig_spec();
  spec.servo.peak_corner_speed = spec.servo.peak_torque_at_max_speed = spec.servo.continuous_torque = std::nan("");
  const ServoSpec derived = Rig(spec).servo();
  EXPECT_NEAR(derived.peak_corner_speed, sv.peak_corner_speed, 1e-12);
  EXPECT_NEAR(derived.peak_torque_at_max_speed, sv.peak_torque_at_max_speed, 1e-12);
  EXPECT_NEAR(derived.continuous_torque, sv.continuous_torque, 0.01);
}

TEST(Mechanism, SingularUJointIsReportedNotHidden) {
  // A leg along its base U-joint's fixed axis: the housing's spin is undefined.
  RigSpec spec = frictionless_spec();
  LegSpec& leg = spec.model.legs[0];
  (void)leg;
  const Rig rig(spec);
  LegState legs;
  ASSERT_EQ(inverse_kinematics(rig.model(), Placement{}, legs), Status::Ok);
  // Aim the leg's axis exactly along ja by editing the state (the geometry cannot reach it).
  legs.s_B.row(0) = rig.model().leg(0).axis_base_B.normalized().transpose();
  Matrix6d J;
  EXPECT_EQ(motor_jacobian(rig, legs, J), Status::SingularBase);
  PlatformMotion bad;
  bad.velocity[0] = std::nan("");
  InverseDynamics id;
  EXPECT_EQ(inverse_dynamics(rig, bad, id), Status::NonFiniteInput);
}

}  // namespace
}  // namespace hexatwist
