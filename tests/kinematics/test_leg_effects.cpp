// SPDX-License-Identifier: BSD-3-Clause
// The legs' effects (leg_effects.hpp, theory §4b): the static forces against the whole
// mechanism's inverse dynamics, each effect's share of the command against its formula, the
// reference state, exact compensation through forward kinematics with the effects, the play's
// direction along a motion, and a model without them unchanged.
#include "support.hpp"

namespace hexatwist::test {
namespace {

// The seed configuration with a `leg_effects` block (the config reader and the Rig's static load).
Config seed_with_effects(const std::string& block) {
  return load_config(std::string(seed_config_yaml()) + "\nleg_effects:\n" + block, "effects.yaml");
}

constexpr const char* kAllEffects =
    "  stiffness: [2.0e8, 1.5e8, 2.5e8, 2.0e8, 1.8e8, 2.2e8]\n"
    "  play: [50.0e-6, 40.0e-6, 60.0e-6, 50.0e-6, 20.0e-6, 80.0e-6]\n"
    "  home_direction: [1, -1, 1, 1, -1, 1]\n"
    "  length_expansion: 11.5e-6\n"
    "  lead_expansion: 11.0e-6\n"
    "  reference_temperature: 20\n";

TEST(LegEffects, StaticForcesAreTheWholeMechanismsInverseDynamicsAtRest) {
  // The nut's axial force at rest from the mechanism's Newton-Euler (inverse_dynamics'
  // screw_force, the motor-side Jacobian, the legs' bodies as rigid bodies) and from
  // static_leg_forces (the length Jacobian, the legs' weight as a force and a moment): they differ
  // by the twist's share of the motor-side Jacobian and the legs' model. Measured on the seed:
  // 1.64e-2 of the force at most (54 N of 3.3 kN: 0.27 um of deflection at 200 N/um).
  const Config config = seed_with_effects("  stiffness: 2.0e8\n");
  const Rig& rig = config.rig;
  std::mt19937_64 rng(kSeed + 401);
  double worst = 0.0;
  for (int n = 0; n < 200; ++n) {
    const Pose p = random_valid_pose(rig.model(), rng, 0.3, deg2rad(20));
    PlatformMotion motion;
    motion.placement = placement_from_pose(p);
    InverseDynamics id;
    ASSERT_EQ(inverse_dynamics(rig, motion, id), Status::Ok);
    Vector6d force;
    ASSERT_EQ(static_leg_forces(rig.model(), rig.model().spec().static_load, id.legs_state, force), Status::Ok);
    EXPECT_TRUE((force.array() < 0.0).all()) << "gravity compresses every leg";
    worst =
        std::max(worst, ((force - id.screw_force).cwiseAbs().array() / id.screw_force.cwiseAbs().array()).maxCoeff());
  }
  report("largest relative difference of the static force from the inverse dynamics", worst);
  EXPECT_LT(worst, 3e-2);
  // At home the reference forces are the model's.
  LegState home;
  ASSERT_EQ(inverse_kinematics(rig.model(), Placement{}, home), Status::Ok);
  Vector6d at_home;
  ASSERT_EQ(static_leg_forces(rig.model(), rig.model().spec().static_load, home, at_home), Status::Ok);
  EXPECT_EQ(at_home, rig.model().reference_force());
  // The seed's 1500 kg and 54 kg legs: 3.2-3.4 kN per leg at rest (the figure).
  EXPECT_GT(-at_home.maxCoeff(), 3.0e3);
  EXPECT_LT(-at_home.minCoeff(), 3.6e3);
}

TEST(LegEffects, StaticForcesBalanceGravityByVirtualWork) {
  // Moving the platform by dx against the legs' forces does the work gravity does: F . dl = G . dx
  // for a central-difference step of the potential energy of the load (legs' bodies massless here).
  ConfigSpec spec = parse_config_spec(seed_config_yaml(), "seed");
  spec.rig.mechanism.housing.mass = 0.0;
  spec.rig.mechanism.rod.mass = 0.0;
  const Rig rig(spec.rig);
  const Model& model = rig.model();
  std::mt19937_64 rng(kSeed + 402);
  for (int n = 0; n < 50; ++n) {
    const Pose p = random_valid_pose(model, rng, 0.3, deg2rad(20));
    LegState legs;
    ASSERT_EQ(inverse_kinematics(model, p, legs), Status::Ok);
    Vector6d force;
    ASSERT_EQ(static_leg_forces(model, model.spec().static_load, legs, force), Status::Ok);
    for (int k = 0; k < 6; ++k) {
      const double h = 1e-5;
      Pose q = p, r = p;
      (k < 3 ? q.position[k] : q.rpy[k - 3]) += h;
      (k < 3 ? r.position[k] : r.rpy[k - 3]) -= h;
      LegState ahead, behind;
      ASSERT_EQ(inverse_kinematics(model, q, ahead), Status::Ok);
      ASSERT_EQ(inverse_kinematics(model, r, behind), Status::Ok);
      const auto height = [&](const Pose& at, const LegState& s) {
        const Vector3d com = s.R_BP * (spec.rig.load.center_of_mass_P - model.spec().pivot_P);
        return (placement_from_pose(at).t + com).z();
      };
      const double work_gravity = -spec.rig.load.mass * spec.rig.load.gravity * (height(q, ahead) - height(r, behind));
      const double work_legs = force.dot(ahead.length - behind.length);
      EXPECT_NEAR(work_legs, work_gravity, 1e-6 * std::abs(work_gravity) + 1e-9) << str(p) << " coordinate " << k;
    }
  }
}

TEST(LegEffects, AtTheReferenceStateTheCommandsAreThoseWithoutEffects) {
  // Home after homing, at the reference temperature, under the configured load: every effect is
  // zero, so the commands are the drives' reference.
  const Config config = seed_with_effects(kAllEffects);
  const Model& model = config.rig.model();
  ASSERT_TRUE(model.has_leg_effects());
  Vector6d command;
  LimitReport report;
  ASSERT_EQ(motor_commands(model, Pose{}, Strategy::Compensated, command, report), Status::Ok);
  EXPECT_LT((command - model.home_command()).cwiseAbs().maxCoeff(), 1e-15);
  CommandReport full;
  ASSERT_EQ(compute_commands(model, Pose{}, full), Status::Ok);
  EXPECT_LT(full.effects.total.cwiseAbs().maxCoeff(), 1e-15);
}

TEST(LegEffects, EachEffectsShareOfTheCommandIsItsFormula) {
  // One effect at a time against a rigid model's command: the deflection c (F - F_ref), the
  // length's and the lead's expansion, the play's jump for an approach against the homing.
  const Config rigid = seed_with_effects("  reference_temperature: 20\n");
  const Pose p{Vector3d(0.05, -0.1, 0.12), Vector3d(deg2rad(5), deg2rad(-3), deg2rad(10))};
  Vector6d base;
  LimitReport report;
  ASSERT_EQ(motor_commands(rigid.rig.model(), p, Strategy::Compensated, base, report), Status::Ok);
  LegState legs;
  ASSERT_EQ(inverse_kinematics(rigid.rig.model(), p, legs), Status::Ok);
  Vector6d dtheta, k_dtheta;
  ASSERT_EQ(twist(rigid.rig.model(), legs, dtheta), Status::Ok);
  length_error(rigid.rig.model(), dtheta, k_dtheta);
  {
    const Config c = seed_with_effects("  stiffness: 2.0e8\n");
    Vector6d command, force;
    ASSERT_EQ(motor_commands(c.rig.model(), p, Strategy::Compensated, command, report), Status::Ok);
    ASSERT_EQ(static_leg_forces(c.rig.model(), c.rig.model().spec().static_load, legs, force), Status::Ok);
    const Vector6d expected = -(force - c.rig.model().reference_force()) / 2.0e8;
    EXPECT_LT((command - base - expected).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_GT(expected.cwiseAbs().maxCoeff(), 1e-7) << "the pose changes the forces";
  }
  {
    // 2 K above the reference: the length grows by a_L l_home dT, the travel from the reference by
    // a_P dT (exactly: u (1 + a_P dT) for the lead's share).
    const Config c = seed_with_effects("  length_expansion: 11.5e-6\n  lead_expansion: 11.0e-6\n");
    const Model& m = c.rig.model();
    LegInputs inputs;
    inputs.temperature.setConstant(22.0);
    Vector6d command;
    ASSERT_EQ(motor_commands(m, p, Strategy::Compensated, inputs, nullptr, command, report), Status::Ok);
    const Vector6d h = m.home_command();
    const Vector6d real_travel = base - h + k_dtheta;  // u0 - h + k dtheta: the rigid leg's
    const Vector6d expected_w = (real_travel - 2.0 * 11.5e-6 * m.length_home()) / (1.0 + 2.0 * 11.0e-6);
    const Vector6d expected = h + expected_w - k_dtheta;
    EXPECT_LT((command - expected).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_GT((command - base).cwiseAbs().minCoeff(), 40e-6) << "about 44 um of growth per leg";
  }
  {
    // Play: a leg approached against its homing direction stops b short: its command is b further.
    const Config c = seed_with_effects("  play: 50.0e-6\n  home_direction: [1, 1, 1, -1, -1, -1]\n");
    Vector6d command;
    ASSERT_EQ(motor_commands(c.rig.model(), p, Strategy::Compensated, command, report), Status::Ok);
    for (int i = 0; i < kLegs; ++i) {
      const double approach = base[i] > c.rig.model().home_command()[i] ? 1.0 : -1.0;
      const double home = i < 3 ? 1.0 : -1.0;
      EXPECT_NEAR(command[i] - base[i], 25e-6 * (approach - home), 1e-15) << "leg " << i + 1;
    }
  }
}

TEST(LegEffects, CompensatedCommandsReachThePoseThroughForwardKinematicsWithTheEffects) {
  // The real legs under the same conditions (forward kinematics with the effects, the forces at
  // the pose it finds): the commanded pose, to the fixed point's and Newton's tolerance.
  const Config config = seed_with_effects(kAllEffects);
  const Model& model = config.rig.model();
  std::mt19937_64 rng(kSeed + 403);
  double worst = 0.0;
  for (int n = 0; n < 300; ++n) {
    const Pose p = random_valid_pose(model, rng, 0.4, deg2rad(25));
    LegInputs inputs;
    for (int i = 0; i < kLegs; ++i) inputs.temperature[i] = 20.0 + 5.0 * std::uniform_real_distribution<>(-1, 1)(rng);
    Vector6d command;
    LimitReport report;
    ASSERT_EQ(motor_commands(model, p, Strategy::Compensated, inputs, nullptr, command, report), Status::Ok) << str(p);
    FkResult fk;
    LegEffects effects;
    ASSERT_EQ(forward_kinematics(model, command, inputs, nullptr, Placement{}, fk, {}, &effects), Status::Ok) << str(p);
    const PoseError e = pose_error(fk.placement, placement_from_pose(p));
    worst = std::max({worst, e.position, e.rotation});
    EXPECT_GT(effects.total.cwiseAbs().maxCoeff(), 1e-6) << "the effects are there";
  }
  report("largest pose error of the round trip with every effect [m, rad]", worst);
  EXPECT_LT(worst, 1e-11);
  // The overloads without conditions take the same defaults: reference temperature, static
  // forces, each leg approached from home.
  const Pose p{Vector3d(0.1, 0.05, -0.1), Vector3d(0.05, 0.1, -0.2)};
  Vector6d command;
  LimitReport report;
  ASSERT_EQ(motor_commands(model, p, Strategy::Compensated, command, report), Status::Ok);
  FkResult fk;
  ASSERT_EQ(forward_kinematics(model, command, LengthKind::Motor, Placement{}, fk), Status::Ok);
  EXPECT_LT(pose_error(fk.placement, placement_from_pose(p)).position, 1e-11);
}

TEST(LegEffects, ThePlayStateKeepsEachLegsDirectionAlongAMotion) {
  // Up along z, then down: every leg lengthens, then shortens; at the reversal its command jumps
  // back by its whole play (the motor crosses the gap), and a pose held keeps the direction.
  const Config config = seed_with_effects("  play: 80.0e-6\n  home_direction: -1\n");
  const Model& model = config.rig.model();
  PlayState play;
  start_play(model, model.home_command(), play);
  EXPECT_EQ(play.direction, Vector6d::Constant(-1.0));
  const auto command_at = [&](double z) {
    Vector6d c;
    LimitReport report;
    EXPECT_EQ(motor_commands(model, Pose{Vector3d(0, 0, z), Vector3d::Zero()}, Strategy::Compensated, LegInputs{},
                             &play, c, report),
              Status::Ok);
    return c;
  };
  Vector6d rigid;
  LimitReport report;
  const Pose up{Vector3d(0, 0, 0.1), Vector3d::Zero()};
  ASSERT_EQ(motor_commands(seed_model(), up, Strategy::Compensated, rigid, report), Status::Ok);
  const Vector6d at_up = command_at(0.1);
  EXPECT_EQ(play.direction, Vector6d::Constant(1.0));
  EXPECT_LT((at_up - rigid - Vector6d::Constant(80e-6)).cwiseAbs().maxCoeff(), 1e-15) << "b / 2 (1 - (-1))";
  const Vector6d held = command_at(0.1);
  EXPECT_EQ(held, at_up) << "a pose held keeps its direction and command";
  Pose down = up;
  down.position.z() = 0.1 - 1e-7;
  const Vector6d back = command_at(down.position.z());
  EXPECT_EQ(play.direction, Vector6d::Constant(-1.0));
  Vector6d rigid_down;
  ASSERT_EQ(motor_commands(seed_model(), down, Strategy::Compensated, rigid_down, report), Status::Ok);
  EXPECT_LT((back - rigid_down).cwiseAbs().maxCoeff(), 1e-15) << "the play crossed: the homing's side again";
  EXPECT_GT((at_up - back).minCoeff(), 80e-6) << "the jump of the play, 0.1 um down";
}

TEST(LegEffects, AModelWithoutEffectsIsUnchangedByTheStaticLoadItCarries) {
  // The seed's configuration carries its static load; its commands and forward kinematics are
  // those of the same model without it, bit for bit.
  ModelSpec bare = seed_model().spec();
  bare.static_load = StaticLoadSpec{};
  const Model without(bare);
  const Config config = default_config();
  const Model& with = config.rig.model();
  ASSERT_TRUE(with.spec().static_load.present);
  ASSERT_FALSE(with.has_leg_effects());
  std::mt19937_64 rng(kSeed + 404);
  for (int n = 0; n < 100; ++n) {
    const Pose p = random_valid_pose(with, rng, 0.4, deg2rad(25));
    Vector6d a, b;
    LimitReport ra, rb;
    ASSERT_EQ(motor_commands(with, p, Strategy::Compensated, a, ra), Status::Ok);
    ASSERT_EQ(motor_commands(without, p, Strategy::Compensated, b, rb), Status::Ok);
    EXPECT_EQ(a, b);
    FkResult fa, fb;
    ASSERT_EQ(forward_kinematics(with, a, LengthKind::Motor, Placement{}, fa), Status::Ok);
    ASSERT_EQ(forward_kinematics(without, b, LengthKind::Motor, Placement{}, fb), Status::Ok);
    EXPECT_EQ(fa.placement.t, fb.placement.t);
    EXPECT_EQ(fa.placement.R_BP, fb.placement.R_BP);
  }
}

TEST(LegEffects, ImplausibleValuesAreRefusedNamingTheField) {
  for (const auto& [block, field] : std::initializer_list<std::pair<const char*, const char*>>{
           {"  stiffness: 1000\n", "leg_effects.stiffness"},
           {"  stiffness: [2e8, 2e8, 2e8, 2e8, 2e8, -1]\n", "leg_effects.stiffness[5]"},
           {"  play: 0.01\n", "leg_effects.play"},
           {"  home_direction: 0\n", "leg_effects.home_direction"},
           {"  length_expansion: 0.5\n", "leg_effects.length_expansion"},
           {"  lead_expansion: [0, 0, 0, 0, 0]\n", "leg_effects.lead_expansion"},
           {"  reference_temperature: 900\n", "leg_effects.reference_temperature"},
           {"  stifness: 2e8\n", "leg_effects.stifness"}}) {
    SCOPED_TRACE(block);
    const std::string text = block;  // clang 14 cannot capture a structured binding
    expect_error_line([&] { (void)seed_with_effects(text); }, "effects.yaml:", {field});
  }
}

}  // namespace
}  // namespace hexatwist::test

namespace hexatwist::test {
namespace {

TEST(LegEffects, AWarmScrewCrossesTheNutsGapInAShorterMotorSideMove) {
  // The gap is b along the thread; a warm lead moves the thread by the motor-side change times
  // 1 + a_P dT, so that b / (1 + a_P dT) of motor-side travel crosses it: exactly what the
  // commands jump by at a reversal (command_travel), and the plant's nuts must agree.
  const Config config = seed_with_effects("  play: 50.0e-6\n  lead_expansion: 11.0e-6\n");
  const Model& model = config.rig.model();
  const Vector6d warm = Vector6d::Constant(model.reference_temperature() + 10.0);
  const double scale = 1.0 + 11.0e-6 * 10.0;
  const Vector6d start = model.home_command();
  NutGap hot, cold;
  EXPECT_EQ(follow_nuts(model, start, warm, hot), Vector6d::Ones()) << "homing leaves each nut on its +1 side";
  (void)follow_nuts(model, start, cold);
  const Vector6d back = start - Vector6d::Constant(50.0e-6 / scale);
  const Vector6d d_hot = follow_nuts(model, back, warm, hot);
  const Vector6d d_cold = follow_nuts(model, back, cold);
  EXPECT_LT((d_hot + Vector6d::Ones()).cwiseAbs().maxCoeff(), 1e-9) << "crossed at the warm lead";
  EXPECT_NEAR(d_cold[0], -1.0 + 2.0 * (1.0 - 1.0 / scale), 1e-9) << "not quite at the reference lead";
  // At the reference temperature both overloads are one.
  NutGap a, b;
  for (const double dz : {0.0, -20e-6, 10e-6, 60e-6, -1e-6})
    EXPECT_EQ(follow_nuts(model, start + Vector6d::Constant(dz), a),
              follow_nuts(model, start + Vector6d::Constant(dz), Vector6d::Constant(model.reference_temperature()), b));
}

}  // namespace
}  // namespace hexatwist::test
