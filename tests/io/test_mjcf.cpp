// SPDX-License-Identifier: BSD-3-Clause
// The MJCF export (mjcf.hpp) loaded in MuJoCo: structure, assembly at home, the twist and the
// screw in the joints at any pose, statics against twist-aware forward kinematics, and the
// motor torques of MuJoCo's inverse dynamics (docs/theory.md §15).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "hexatwist/dynamics/mechanism.hpp"
#include "mjcf_support.hpp"
#include "support.hpp"

namespace hexatwist::test {
namespace {

// The seed configuration with `from` replaced by `to` in its text.
Config seed_variant(const std::string& from, const std::string& to) {
  std::string text(seed_config_yaml());
  const auto k = text.find(from);
  if (k == std::string::npos) throw std::runtime_error("seed.yaml has no " + from);
  text.replace(k, from.size(), to);
  return load_config(text, "variant.yaml");
}

// Seed (base-driven, right-hand) and the mirror case (platform-driven, left-hand thread, gear 2).
std::vector<std::pair<std::string, Rig>> rigs() {
  std::vector<std::pair<std::string, Rig>> r;
  r.emplace_back("seed", default_config().rig);
  Config c = seed_variant("driven_side: base", "driven_side: platform");
  RigSpec spec{c.rig.model().spec(), c.rig.servo(), c.rig.load(), c.rig.simulation(), c.rig.mechanism()};
  for (LegSpec& leg : spec.model.legs) leg.thread = ThreadSense::Left;
  spec.servo.gear_ratio = 2.0;
  spec.model.legs[2].length_offset = 0.002;
  r.emplace_back("platform-driven left-hand gear 2", Rig(spec));
  return r;
}

std::string fmt_vector(const Vector6d& v) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "[%.3f %.3f %.3f %.3f %.3f %.3f]", v[0], v[1], v[2], v[3], v[4], v[5]);
  return buf;
}

Placement placement(double x, double y, double z, double roll_deg, double pitch_deg, double yaw_deg) {
  return placement_from_pose(
      Pose{Vector3d(x, y, z), Vector3d(deg2rad(roll_deg), deg2rad(pitch_deg), deg2rad(yaw_deg))});
}

// Poses the platform at `x` from wherever the legs are, in `steps` stages, solving the legs each time.
double pose_and_solve(MjSim& sim, const Model& model, const Placement& x, int steps = 4) {
  mj_kinematics(sim.m, sim.d);
  const Placement from = sim.platform(model);
  const Eigen::AngleAxisd rot(from.R_BP.transpose() * x.R_BP);
  double r = 0.0;
  for (int k = 1; k <= steps; ++k) {
    const double f = static_cast<double>(k) / steps;
    Placement xk;
    xk.t = from.t + f * (x.t - from.t);
    xk.R_BP = from.R_BP * Eigen::AngleAxisd(f * rot.angle(), rot.axis()).toRotationMatrix();
    sim.set_platform(model, xk);
    r = sim.solve_legs();
  }
  return r;
}

TEST(Mjcf, LoadsWithTheExpectedSizesAndMass) {
  for (const auto& [name, rig] : rigs()) {
    SCOPED_TRACE(name);
    MjSim sim(mjcf_model(rig));
    EXPECT_EQ(sim.m->nq, 7 + 6 * 8);
    EXPECT_EQ(sim.m->nv, 6 + 6 * 8);
    EXPECT_EQ(sim.m->nu, 6);
    EXPECT_EQ(sim.m->neq, 18);
    const double tiny = 0.0;
    EXPECT_NEAR(mj_getTotalmass(sim.m),
                rig.load().mass + 6 * (rig.mechanism().housing.mass + rig.mechanism().rod.mass) + tiny, 1e-9);
    for (int i = 1; i <= 6; ++i) {
      const std::string n = std::to_string(i);
      for (const char* j : {"_ja", "_jb", "_screw", "_nut", "_slide", "_je", "_jd", "_rotor"})
        EXPECT_NO_THROW((void)sim.id(mjOBJ_JOINT, "leg" + n + j));
      for (const std::string b : {"housing", "rotor", "screw", "rod", "end"})
        EXPECT_NO_THROW((void)sim.id(mjOBJ_BODY, b + n));
      EXPECT_NO_THROW((void)sim.id(mjOBJ_ACTUATOR, "motor" + n));
    }
  }
}

TEST(Mjcf, AtHomeEveryEqualityHoldsAndTheJointsAreWhereTheModelPutsThem) {
  for (const auto& [name, rig] : rigs()) {
    SCOPED_TRACE(name);
    const Model& model = rig.model();
    MjSim sim(mjcf_model(rig));
    mj_forward(sim.m, sim.d);
    EXPECT_EQ(sim.d->ne, 6 * 6 + 12);                                  // six welds and twelve joint equalities
    EXPECT_EQ(sim.d->nf, rig.servo().coulomb_friction > 0.0 ? 6 : 0);  // the rotors' dry friction
    report("max |efc_pos| at qpos0 [m or rad]", sim.max_residual());
    EXPECT_LT(sim.max_residual(), 1e-14);
    LegState legs;
    ASSERT_EQ(inverse_kinematics(model, Placement{}, legs), Status::Ok);
    for (int i = 0; i < 6; ++i) {
      const std::string n = std::to_string(i + 1);
      const Vector3d housing = Eigen::Map<const Vector3d>(sim.d->xpos + 3 * sim.id(mjOBJ_BODY, "housing" + n));
      const Vector3d end = Eigen::Map<const Vector3d>(sim.d->xpos + 3 * sim.id(mjOBJ_BODY, "end" + n));
      EXPECT_LT((housing - model.leg(i).base_B).norm(), 1e-15);
      EXPECT_LT((end - model.leg(i).base_B - legs.leg_B.row(i).transpose()).norm(), 1e-14);
    }
    EXPECT_LT((sim.platform(model).t).norm(), 1e-15);
  }
}

TEST(Mjcf, JointsCarryTheTwistTheLengthAndTheMotorAngleAtAnyPose) {
  for (const auto& [name, rig] : rigs()) {
    SCOPED_TRACE(name);
    const Model& model = rig.model();
    MjSim sim(mjcf_model(rig));
    double worst_twist = 0.0, worst_length = 0.0, worst_motor = 0.0, worst_joint = 0.0, worst_efc = 0.0;
    for (const Placement& x : {placement(0.1, 0.0, 0.0, 0.0, 0.0, 20.0), placement(-0.2, 0.1, 0.15, 5.0, -8.0, -25.0),
                               placement(0.0, -0.3, -0.2, -10.0, 6.0, 10.0)}) {
      worst_efc = std::max(worst_efc, pose_and_solve(sim, model, x));
      LegState legs;
      Vector6d dtheta;
      ASSERT_EQ(inverse_kinematics(model, x, legs), Status::Ok);
      ASSERT_EQ(twist(model, legs, dtheta), Status::Ok);
      const Vector6d phi = motor_angles_of(rig, x);
      for (int i = 0; i < 6; ++i) {
        const std::string n = "leg" + std::to_string(i + 1);
        worst_twist = std::max(worst_twist, std::abs(sim.q(n + "_screw") + sim.q(n + "_nut") - dtheta[i]));
        worst_length =
            std::max(worst_length, std::abs(sim.q(n + "_slide") - (legs.length[i] - model.leg(i).length_home)));
        worst_motor = std::max(worst_motor, std::abs(sim.q(n + "_rotor") - rotor_angle(model.leg(i), phi[i])));
        const Vector3d end =
            Eigen::Map<const Vector3d>(sim.d->xpos + 3 * sim.id(mjOBJ_BODY, "end" + std::to_string(i + 1)));
        worst_joint = std::max(worst_joint, (end - model.leg(i).base_B - legs.leg_B.row(i).transpose()).norm());
      }
    }
    report("max |efc_pos| after solving the legs", worst_efc);
    report("twist: |screw + nut - dtheta| [rad]", worst_twist);
    report("length: |slide - (l - l_home)| [m]", worst_length);
    report("motor: |rotor - (+-phi)| [rad]", worst_motor);
    report("platform joint position [m]", worst_joint);
    EXPECT_LT(worst_efc, 1e-13);
    EXPECT_LT(worst_twist, 1e-9);
    EXPECT_LT(worst_length, 1e-11);
    EXPECT_LT(worst_motor, 1e-9);
    EXPECT_LT(worst_joint, 1e-11);
  }
}

// The text of `xml` with one more equality per leg, "legN_hold", that holds the rotor (at 0 until
// eq_data is set).
std::string with_rotors_held(std::string xml) {
  std::string locks;
  for (int i = 0; i < 6; ++i)
    locks += "    <joint name=\"leg" + std::to_string(i + 1) + "_hold\" joint1=\"leg" + std::to_string(i + 1) +
             "_rotor\" polycoef=\"" + std::to_string(0.0) + " 0 0 0 0\"/>\n";
  xml.replace(xml.find("  </equality>"), 0, locks);
  return xml;
}

struct Settled {
  Placement placement;
  double speed = 0.0;     // largest |qvel| at the end [m/s, rad/s]
  double residual = 0.0;  // largest |efc_pos| at the end
  int steps = 0;
};

// Holds the rotors at the motor angles `phi`, starts from `start` (legs solved with the holds
// off), and lets gravity act with damping on every joint until the platform rests. With
// `twist_free`, each leg's screw is taken out: the slide follows the motor alone
// (slide = c phi, as rotor = +-slide / c) and the nut turns freely, the plant of a conventional (twist-blind) model.
Settled settle(const Rig& rig, const Vector6d& phi, const Placement& start, bool twist_free) {
  const Model& model = rig.model();
  MjSim sim(with_rotors_held(mjcf_model(rig)));
  std::vector<int> holds;
  for (int i = 0; i < 6; ++i) {
    const std::string n = "leg" + std::to_string(i + 1);
    const int h = sim.id(mjOBJ_EQUALITY, n + "_hold");
    sim.m->eq_data[h * mjNEQDATA] = rotor_angle(model.leg(i), phi[i]);
    holds.push_back(h);
    if (twist_free) {
      const int e = sim.id(mjOBJ_EQUALITY, n + "_helix");
      // rotor = +-slide / c, in radians like the model's own helix (docs/theory.md §15).
      sim.m->eq_obj1id[e] = sim.id(mjOBJ_JOINT, n + "_rotor");
      sim.m->eq_obj2id[e] = sim.id(mjOBJ_JOINT, n + "_slide");
      sim.m->eq_data[e * mjNEQDATA + 1] = rotor_angle(model.leg(i), 1.0) / rig.motor_gain()[i];
    }
  }
  for (const int h : holds) sim.m->eq_active[h] = 0;
  // Start: the platform at `start`, the rotors where they must be there, then the holds on.
  sim.set_platform(model, start);
  if (pose_and_solve(sim, model, start) > 1e-12) throw std::runtime_error("legs not solved at the start");
  for (const int h : holds) sim.m->eq_active[h] = 1;
  for (int k = 0; k < sim.m->nv; ++k) sim.m->dof_damping[k] = 200.0;
  for (int k = 0; k < 6; ++k) sim.m->dof_damping[sim.platform_dof() + k] = 2e4;
  Settled out;
  for (out.steps = 0; out.steps < 60000; ++out.steps) {
    mj_step(sim.m, sim.d);
    double v = 0.0;
    for (int k = 0; k < sim.m->nv; ++k) v = std::max(v, std::abs(sim.d->qvel[k]));
    out.speed = v;
    if (out.steps > 100 && v < 1e-10) break;
  }
  mj_forward(sim.m, sim.d);
  out.placement = sim.platform(model);
  out.residual = sim.max_residual();
  return out;
}

double rotation_angle(const Matrix3d& A, const Matrix3d& B) { return Eigen::AngleAxisd(A.transpose() * B).angle(); }

TEST(Mjcf, WithTheMotorsHeldThePlatformRestsAtTwistAwareForwardKinematics) {
  for (const auto& [name, rig] : rigs()) {
    SCOPED_TRACE(name);
    const Model& model = rig.model();
    const Placement target = placement(0.08, -0.05, 0.05, 3.0, -2.0, 15.0);
    const Vector6d phi = motor_angles_of(rig, target);
    // hexatwist's pose for these motor angles: forward kinematics of the motor-side lengths.
    const Vector6d m = model.length_home() - model.geometry().length_offset + rig.motor_gain().cwiseProduct(phi);
    FkResult fk;
    ASSERT_EQ(forward_kinematics(model, m, LengthKind::Motor, Placement{}, fk), Status::Ok);
    FkResult geometric;  // the pose of a twist-blind plant: |L| = m + offset
    ASSERT_EQ(
        forward_kinematics(model, m + model.geometry().length_offset, LengthKind::Geometric, Placement{}, geometric),
        Status::Ok);
    // Start 2 mm and 0.2 deg away from both.
    Placement start = geometric.placement;
    start.t += Vector3d(0.002, -0.001, 0.001);
    start.R_BP = exp_so3(Vector3d(0.0, 0.0, deg2rad(0.2))) * start.R_BP;

    const Settled s = settle(rig, phi, start, false);
    const double dt = (s.placement.t - fk.placement.t).norm();
    const double dr = rotation_angle(s.placement.R_BP, fk.placement.R_BP);
    std::printf("  %s: settled in %d steps, max |qvel| %.2g, max |efc_pos| %.2g\n", name.c_str(), s.steps, s.speed,
                s.residual);
    report("|t_mujoco - t_fk| [m]", dt);
    report("rotation between them [rad]", dr);
    EXPECT_LT(dt, 4e-8);  // measured 3.5e-9 m, 3.0e-10 rad: the equalities' softness under the load
    EXPECT_LT(dr, 4e-9);

    const Settled blind = settle(rig, phi, start, true);
    const double dt_blind = (blind.placement.t - fk.placement.t).norm();
    report("twist coupling removed: |t_mujoco - t_fk| [m]", dt_blind);
    report("twist coupling removed: |t_mujoco - t_geometric_fk| [m]",
           (blind.placement.t - geometric.placement.t).norm());
    EXPECT_GT(dt_blind, 50e-6);
    EXPECT_LT((blind.placement.t - geometric.placement.t).norm(), 4e-8);
  }
}

}  // namespace
}  // namespace hexatwist::test

namespace hexatwist::test {
namespace {

TEST(Mjcf, ALegBodyLighterAcrossThanItsRotorAndScrewIsRefusedNamingTheField) {
  const Rig seed = default_config().rig;
  MechanismSpec mech = seed.mechanism();
  mech.housing.transverse_inertia = 1e-3;  // less than (J_m + J_s) / 2 = 1.1e-3
  const Rig rig(seed.model(), seed.servo(), seed.load(), seed.simulation(), mech);
  expect_error_line([&] { (void)mjcf_model(rig); }, "mechanism.housing.transverse_inertia:", {"rotor", "rigid"});
}

}  // namespace
}  // namespace hexatwist::test

namespace hexatwist::test {
namespace {

// A fast motion: x 0.2 m and yaw 25 deg at 0.6 Hz (0.75 m/s, 94 deg/s), with heave and roll.
struct FastMotion {
  static constexpr double w = 2.0 * kPi * 0.6;  // [rad/s]
  Vector6d amplitude = (Vector6d() << 0.2, 0.0, 0.05, deg2rad(4.0), 0.0, deg2rad(25.0)).finished();
  Vector6d frequency = (Vector6d() << 1.0, 1.0, 2.0, 1.0, 1.0, 1.0).finished();
  Vector6d phase = (Vector6d() << 0.0, 0.0, 0.3, 1.0, 0.0, 0.5).finished();
  // Pose [m, rad] and its first and second time derivatives at t.
  void at(double t, Vector6d& q, Vector6d& qd, Vector6d& qdd) const {
    for (int k = 0; k < 6; ++k) {
      const double a = frequency[k] * w;
      q[k] = amplitude[k] * std::sin(a * t + phase[k]);
      qd[k] = amplitude[k] * a * std::cos(a * t + phase[k]);
      qdd[k] = -amplitude[k] * a * a * std::sin(a * t + phase[k]);
    }
  }
  Placement placement(double t) const {
    Vector6d q, qd, qdd;
    at(t, q, qd, qdd);
    return placement_from_pose(Pose{q.head<3>(), q.tail<3>()});
  }
};

TEST(Mjcf, MujocoInverseDynamicsGivesHexatwistsMotorTorquesWithoutFriction) {
  RigSpec spec{default_config().rig.model().spec(), default_config().rig.servo(), default_config().rig.load(),
               default_config().rig.simulation(), default_config().rig.mechanism()};
  spec.servo.viscous_friction = spec.servo.coulomb_friction = 0.0;
  spec.mechanism.efficiency = spec.mechanism.back_efficiency = 1.0;
  const Rig rig(spec);
  const Model& model = rig.model();
  MjSim sim(mjcf_model(rig));
  const FastMotion motion;
  const double h = 2e-4, period = 1.0 / 0.6;
  const int nv = sim.m->nv, nq = sim.m->nq;
  Eigen::VectorXd q_minus(nq), q0(nq), q_plus(nq), v1(nv), v2(nv), qvel(nv), qacc(nv);
  double worst = 0.0, peak = 0.0;
  for (int k = 0; k < 50; ++k) {
    const double t = period * k / 50.0;
    for (auto [dt, q] : {std::pair{-h, &q_minus}, std::pair{0.0, &q0}, std::pair{h, &q_plus}}) {
      ASSERT_LT(pose_and_solve(sim, model, motion.placement(t + dt), k == 0 && dt < 0 ? 4 : 1), 1e-12);
      *q = Eigen::Map<const Eigen::VectorXd>(sim.d->qpos, nq);
    }
    mj_differentiatePos(sim.m, qvel.data(), 2.0 * h, q_minus.data(), q_plus.data());
    mj_differentiatePos(sim.m, v1.data(), h, q_minus.data(), q0.data());
    mj_differentiatePos(sim.m, v2.data(), h, q0.data(), q_plus.data());
    qacc = (v2 - v1) / h;
    Eigen::Map<Eigen::VectorXd>(sim.d->qpos, nq) = q0;
    Eigen::Map<Eigen::VectorXd>(sim.d->qvel, nv) = qvel;
    Eigen::Map<Eigen::VectorXd>(sim.d->qacc, nv) = qacc;
    mj_inverse(sim.m, sim.d);
    // qfrc_inverse = Jc^T lambda + (actuator moments)^T tau.
    const int ne = sim.d->ne;  // the equality rows (the test's rig has no friction rows)
    ASSERT_EQ(sim.d->nefc, ne);
    Eigen::MatrixXd A(nv, ne + 6);
    A.leftCols(ne) =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(sim.d->efc_J, ne, nv)
            .transpose();
    A.rightCols(6) = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
                         sim.d->actuator_moment, 6, nv)
                         .transpose();
    const Eigen::VectorXd x = A.colPivHouseholderQr().solve(Eigen::Map<const Eigen::VectorXd>(sim.d->qfrc_inverse, nv));
    const Vector6d tau_mj = x.tail(6);

    Vector6d q, qd, qdd;
    motion.at(t, q, qd, qdd);
    const PlatformMotion pm = platform_motion(Pose{q.head<3>(), q.tail<3>()}, qd, qdd);
    InverseDynamics id;
    ASSERT_EQ(inverse_dynamics(rig, pm, id), Status::Ok);
    worst = std::max(worst, (tau_mj - id.torque).cwiseAbs().maxCoeff());
    peak = std::max(peak, id.torque.cwiseAbs().maxCoeff());
    if (k % 10 == 0)
      std::printf("  t %.3f s: |v| %.3f m/s, |w| %.1f deg/s, tau_hx %s, max |tau_mj - tau_hx| %.3g N m\n", t,
                  pm.velocity.head<3>().norm(), rad2deg(pm.velocity.tail<3>().norm()), fmt_vector(id.torque).c_str(),
                  (tau_mj - id.torque).cwiseAbs().maxCoeff());
  }
  report("max |tau_mujoco - tau_hexatwist| [N m]", worst);
  report("peak |tau_hexatwist| [N m]", peak);
  EXPECT_LT(worst, 1e-6 * peak);  // measured 2.3e-6 N m of 23 N m (the issue asked for 0.5 %)
}

}  // namespace
}  // namespace hexatwist::test
