// SPDX-License-Identifier: BSD-3-Clause
// What the legs' effects cost at point A (effect_cost.hpp): one row per effect in order, exact
// compensation of each (the compensated commands on the plant with the effect leave the forward
// kinematics' tolerance), the load's cost against geometric forward kinematics of the deflected
// lengths (an independent route), the warm-up's history, and the refusals.
#include "support.hpp"

#include "hexatwist/dynamics/leg_forces.hpp"
#include "hexatwist/simulation/effect_cost.hpp"

namespace hexatwist::test {
namespace {

Config seed_with_effects(const std::string& block) {
  return load_config(std::string(seed_config_yaml()) + "\nleg_effects:\n" + block, "effects.yaml");
}

constexpr const char* kEffects =
    "  stiffness: 2.0e8\n"
    "  play: [50.0e-6, 40.0e-6, 60.0e-6, 50.0e-6, 20.0e-6, 80.0e-6]\n"
    "  length_expansion: 11.5e-6\n"
    "  lead_expansion: 11.0e-6\n";

// A study test at 100 Hz: the sweep's shape at a tenth of the control rate's samples.
Trajectory test_at_100hz(const char* name) { return test_trajectory(StudySpec{}, study_test(StudySpec{}, name), 0.01); }

TEST(EffectCost, TheWarmUpRisesFromZeroToOneAlongItsExponential) {
  EXPECT_EQ(warm_up_share(0.0, 10.0), 0.0);
  EXPECT_NEAR(warm_up_share(10.0, 10.0), 1.0, 1e-15);
  EXPECT_EQ(warm_up_share(3.0, 0.0), 0.0) << "a run of no duration does not warm";
  double last = 0.0;
  for (int k = 1; k <= 100; ++k) {
    const double s = warm_up_share(0.1 * k, 10.0);
    EXPECT_GT(s, last);
    EXPECT_LT(s - last, 0.1 * 1.6 / 10.0) << "its slope at most 1 / (T (1 - 1/e))";
    last = s;
  }
}

TEST(EffectCost, RigidLegsHaveNoRowAndABadRiseIsRefused) {
  std::vector<EffectCost> rows{EffectCost{}};
  SimulationIssue issue;
  ASSERT_EQ(effect_costs(seed_rig(), test_at_100hz("Rz"), Vector6d::Zero(), rows, issue), Status::Ok);
  EXPECT_TRUE(rows.empty()) << "rigid legs: nothing to cost";
  EXPECT_EQ(effect_costs(seed_rig(), test_at_100hz("Rz"), Vector6d::Constant(2.0), rows, issue),
            Status::InvalidArgument)
      << "a warm-up of legs that do not expand";
  EXPECT_NE(check_temperature_rise(seed_model(), Vector6d::Constant(2.0)).find("do not expand"), std::string::npos);
  const Config config = seed_with_effects(kEffects);
  for (const double bad : {kMaxTemperatureRise * 1.01, -kMaxTemperatureRise * 1.01, std::nan("")}) {
    EXPECT_EQ(effect_costs(config.rig, test_at_100hz("Rz"), Vector6d::Constant(bad), rows, issue),
              Status::InvalidArgument)
        << bad;
    EXPECT_TRUE(rows.empty());
  }
}

TEST(EffectCost, EachEffectCostsMicrometresAndItsCompensationRemovesIt) {
  const Config config = seed_with_effects(kEffects);
  std::vector<EffectCost> rows;
  SimulationIssue issue;
  for (const char* name : {"Lz", "Lx", "Rz", "Ry"}) {
    SCOPED_TRACE(name);
    const Trajectory trajectory = test_at_100hz(name);
    ASSERT_EQ(effect_costs(config.rig, trajectory, Vector6d::Constant(2.0), rows, issue), Status::Ok)
        << to_string(issue.status) << " at t = " << issue.time;
    ASSERT_EQ(rows.size(), 4u);
    const char* order[] = {"load", "play", "heat", "all"};
    double worst_compensated = 0.0;
    for (std::size_t r = 0; r < rows.size(); ++r) {
      SCOPED_TRACE(rows[r].effect);
      EXPECT_EQ(rows[r].effect, order[r]);
      // Left uncompensated, each effect moves point A by micrometres (2 K on 1.9 m legs: 44 um;
      // 50 um of play; a few kN on 200 N/um: the force's change over the sweep).
      EXPECT_GT(rows[r].twist_compensated.max, 2e-6);
      EXPECT_LT(rows[r].twist_compensated.max, 1e-3);
      EXPECT_GE(rows[r].twist_compensated.max, rows[r].twist_compensated.rms);
      // The conventional commands leave the twist's error as well (tens of um to a millimetre).
      EXPECT_GT(rows[r].conventional.max, rows[r].twist_compensated.max * 0.5);
      worst_compensated = std::max(worst_compensated, rows[r].compensated.max);
    }
    report("compensated, worst row [m]", worst_compensated);
    EXPECT_LT(worst_compensated, 2e-11) << "compensated: the forward kinematics' tolerance (measured 1.9e-12)";
  }
}

TEST(EffectCost, TheLoadsCostIsTheGeometricPoseOfTheDeflectedLengths) {
  // Independent route: a rigid-leg command sent to legs deflected by (F - F_home) / k puts the
  // platform where geometric forward kinematics of the rigid IK lengths plus that deflection says
  // (the twist compensated at the commanded pose; the twist's change over the um of the
  // deflection, 1e-5 rad x 1.6 mm/rad, is the residual). F: the static force at the pose plus the
  // motion's share, from the inverse dynamics at the trajectory's differences. The commands that
  // know only the static load leave that share's deflection: the geometric route gives it too.
  const Config config = seed_with_effects("  stiffness: 2.0e8\n");
  const Model& model = config.rig.model();
  const Trajectory trajectory = test_at_100hz("Lx");
  std::vector<EffectCost> rows;
  SimulationIssue issue;
  ASSERT_EQ(effect_costs(config.rig, trajectory, Vector6d::Zero(), rows, issue), Status::Ok);
  ASSERT_EQ(rows.size(), 1u);
  LegState home;
  ASSERT_EQ(inverse_kinematics(model, Placement{}, home), Status::Ok);
  Vector6d f_home;
  ASSERT_EQ(static_leg_forces(model, model.spec().static_load, home, f_home), Status::Ok);
  const Vector3d& a = model.spec().observation_P;
  std::vector<double> error, inertial_error;
  FkResult fk;
  for (std::size_t k = 0; k < trajectory.poses.size(); ++k) {
    const Placement x = placement_from_pose(trajectory.poses[k]);
    LegState legs;
    ASSERT_EQ(inverse_kinematics(model, x, legs), Status::Ok);
    Vector6d f, inertial;
    ASSERT_EQ(static_leg_forces(model, model.spec().static_load, legs, f), Status::Ok);
    ASSERT_EQ(inertial_leg_forces(config.rig, trajectory_motion(trajectory, k), inertial), Status::Ok);
    ASSERT_EQ(forward_kinematics(model, Vector6d(legs.length + (f + inertial - f_home) / 2.0e8), LengthKind::Geometric,
                                 x, fk),
              Status::Ok);
    error.push_back((platform_point_B(model, fk.placement, a) - platform_point_B(model, x, a)).norm());
    ASSERT_EQ(forward_kinematics(model, Vector6d(legs.length + inertial / 2.0e8), LengthKind::Geometric, x, fk),
              Status::Ok);
    inertial_error.push_back((platform_point_B(model, fk.placement, a) - platform_point_B(model, x, a)).norm());
  }
  const ErrorStats independent = error_stats(error), inertial = error_stats(inertial_error);
  report("load's cost, max [m]", rows[0].twist_compensated.max);
  report("against geometric FK [m]", std::abs(rows[0].twist_compensated.max - independent.max));
  report("the static load's commands, max [m]", rows[0].static_load_compensated.max);
  report("against geometric FK [m]", std::abs(rows[0].static_load_compensated.max - inertial.max));
  EXPECT_GT(independent.max, 2e-6);
  EXPECT_NEAR(rows[0].twist_compensated.max, independent.max, 1e-8);
  EXPECT_NEAR(rows[0].twist_compensated.rms, independent.rms, 1e-8);
  EXPECT_GT(inertial.max, 2e-7) << "the sweep's accelerations deflect the legs";
  EXPECT_NEAR(rows[0].static_load_compensated.max, inertial.max, 1e-8);
  EXPECT_NEAR(rows[0].static_load_compensated.rms, inertial.rms, 1e-8);
  EXPECT_LT(rows[0].compensated.max, 2e-11) << "the commands that know the forces leave the FK's tolerance";
}

TEST(EffectCost, HeatGrowsLinearlyWithTheRiseAndNeedsOne) {
  const Config config = seed_with_effects("  length_expansion: 11.5e-6\n  lead_expansion: 11.0e-6\n");
  const Trajectory trajectory = test_at_100hz("Rz");
  std::vector<EffectCost> one, two;
  SimulationIssue issue;
  ASSERT_EQ(effect_costs(config.rig, trajectory, Vector6d::Constant(1.0), one, issue), Status::Ok);
  ASSERT_EQ(effect_costs(config.rig, trajectory, Vector6d::Constant(2.0), two, issue), Status::Ok);
  ASSERT_EQ(one.size(), 1u);
  ASSERT_EQ(two.size(), 1u);
  EXPECT_EQ(two[0].effect, "heat");
  // Linear in the rise to first order: the expansion is 2e-5 of the length.
  EXPECT_NEAR(two[0].twist_compensated.max / one[0].twist_compensated.max, 2.0, 1e-3);
  EXPECT_GT(two[0].twist_compensated.max, 30e-6) << "2 K on 1.9 m of steel: 44 um of growth per leg";
  std::vector<EffectCost> none;
  ASSERT_EQ(effect_costs(config.rig, trajectory, Vector6d::Zero(), none, issue), Status::Ok);
  EXPECT_TRUE(none.empty()) << "legs that expand but do not warm cost nothing";
}

}  // namespace
}  // namespace hexatwist::test
