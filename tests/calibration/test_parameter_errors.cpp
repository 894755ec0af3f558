// SPDX-License-Identifier: BSD-3-Clause
// The real platform against the model (parameter_errors.hpp): each error changes what it should and
// nothing else; the drives keep their lead and reference, so the nominal commands move the real nut
// by the real lead about that reference; joint errors have no rigid part (the gauge of theory §13).
#include <gtest/gtest.h>

#include "hexatwist/hexatwist.hpp"
#include "support.hpp"

namespace hexatwist {
namespace {

using test::seed_model;

TEST(ParameterErrors, NoErrorIsTheNominalPlatform) {
  const Model& nominal = seed_model();
  const Model real = real_model(nominal, ParameterErrors{});
  EXPECT_EQ(real.geometry().twist_gain, nominal.geometry().twist_gain);
  EXPECT_EQ(real.length_home(), nominal.length_home());
  EXPECT_EQ(real.home_command(), nominal.home_command());
  EXPECT_FALSE(real.has_drive_scale());
  EXPECT_EQ(real.spec().observation_P, nominal.spec().observation_P);
  Vector6d m;
  m << 1.7, 1.8, 1.9, 2.0, 2.1, 2.2;
  EXPECT_EQ(real.travel_from_motor(m), m);
}

TEST(ParameterErrors, EachErrorChangesItsOwnParameter) {
  const Model& nominal = seed_model();
  ParameterErrors e;
  e.lead_error.setConstant(0.05);
  const Model longer = real_model(nominal, e);
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_DOUBLE_EQ(longer.leg(i).lead, 1.05 * nominal.leg(i).lead);
    EXPECT_DOUBLE_EQ(longer.leg(i).twist_gain, 1.05 * nominal.leg(i).twist_gain);  // Eq. (10) scales with the lead
    EXPECT_DOUBLE_EQ(longer.leg(i).drive_scale, 1.05);                             // the drive keeps the nominal lead
  }
  EXPECT_EQ(longer.length_home(), nominal.length_home());
  e = ParameterErrors{};
  e.flip_twist_sign = true;
  const Model flipped = real_model(nominal, e);
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_EQ(flipped.leg(i).twist_gain, -nominal.leg(i).twist_gain);
    EXPECT_NE(flipped.leg(i).thread, nominal.leg(i).thread);
  }
  e = ParameterErrors{};
  e.observation_offset_P = Vector3d(0.001, -0.002, 0.003);
  EXPECT_EQ(real_model(nominal, e).spec().observation_P, nominal.spec().observation_P + e.observation_offset_P);
  e = ParameterErrors{};
  e.zero_offset << 1e-3, -1e-3, 0.5e-3, 0, 2e-4, -7e-4;
  EXPECT_EQ(real_model(nominal, e).geometry().length_offset, e.zero_offset);
  e = ParameterErrors{};
  e.base_offset_B(2, 1) = 1e-3;
  e.platform_axis_rotation(4, 0) = 0.01;
  const Model moved = real_model(nominal, e);
  EXPECT_EQ(moved.leg(2).base_B, nominal.leg(2).base_B + Vector3d(0, 1e-3, 0));
  EXPECT_LT((moved.leg(4).axis_platform_P - exp_so3(Vector3d(0.01, 0, 0)) * nominal.leg(4).axis_platform_P)
                .cwiseAbs()
                .maxCoeff(),
            1e-15);
  e = ParameterErrors{};
  e.lead_error[3] = -1.5;
  EXPECT_THROW((void)real_model(nominal, e), Error);  // a negative lead
}

TEST(ParameterErrors, TheNominalCommandsMoveTheRealNutByTheRealLeadAboutTheReference) {
  // The drive reads the nominal reference at home and converts lengths with the nominal lead: 0.1 m
  // of commanded travel is 0.102 m of real travel with a 2 % longer lead; the offsets add to it.
  const Model& nominal = seed_model();
  ParameterErrors e;
  e.lead_error.setConstant(0.02);
  e.zero_offset << 1e-3, -1e-3, 0.5e-3, 0, 2e-4, -7e-4;
  const Model real = real_model(nominal, e);
  const Vector6d h = nominal.home_command();
  EXPECT_LT((real.travel_from_motor(h) - h).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((real.travel_from_motor(h + Vector6d::Constant(0.1)) - h - Vector6d::Constant(0.102)).cwiseAbs().maxCoeff(),
            1e-15);
  EXPECT_EQ(real.geometry().length_offset, e.zero_offset);
}

TEST(ParameterErrors, TheRealPlatformRunsWhereItsOwnCommandsSay) {
  // A controller that knew the real platform would command it exactly: its compensated commands
  // (real model, drives' reference and scale included) through its motor-side FK return the pose.
  const Model& nominal = seed_model();
  ParameterErrors e;
  e.lead_error.setConstant(0.03);
  e.flip_twist_sign = true;
  e.zero_offset << 1e-3, -1e-3, 0.5e-3, 0, 2e-4, -7e-4;
  random_geometry_errors(nominal, 2e-3, deg2rad(1.0), 5, e);
  const Model real = real_model(nominal, e);
  std::mt19937_64 rng(test::kSeed + 501);
  double worst = 0.0;
  for (int n = 0; n < test::stress(200); ++n) {
    const Pose pose = test::random_valid_pose(real, rng, 0.2, deg2rad(15));
    Vector6d command;
    LimitReport limit;
    ASSERT_EQ(motor_commands(real, pose, Strategy::Compensated, command, limit), Status::Ok);
    FkResult fk;
    ASSERT_EQ(forward_kinematics(real, command, LengthKind::Motor, Placement{}, fk), Status::Ok);
    worst = std::max(worst, (fk.pose.to_vector() - pose.to_vector()).cwiseAbs().maxCoeff());
  }
  test::report("pose error [m, rad]", worst);
  EXPECT_LT(worst, 1e-11);
}

TEST(ParameterErrors, JointErrorsHaveNoRigidPartSoTheFramesStayTheLeastSquaresFramesOfTheJoints) {
  // Theory §13: the least-squares (Kabsch) frame of the moved joints is the frame of the nominal
  // ones, for random displacements of millimetres; the displacements keep their non-rigid part.
  const Model& nominal = seed_model();
  ParameterErrors e;
  random_geometry_errors(nominal, 2e-3, 0.0, 77, e);
  for (const auto& [points, d] : {std::pair{nominal.geometry().base_B, e.base_offset_B},
                                  std::pair{nominal.geometry().arm_P, e.platform_offset_P}}) {
    std::vector<PointPair> pairs;
    for (int i = 0; i < kLegs; ++i)
      pairs.push_back({Vector3d((points.row(i) + d.row(i)).transpose()), Vector3d(points.row(i).transpose())});
    Registration reg;
    ASSERT_EQ(register_points(pairs, reg), Status::Ok);
    EXPECT_LT((reg.X_BT.R - Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT(reg.X_BT.t.cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_GT(d.cwiseAbs().maxCoeff(), 0.5e-3);
    // Removing the rigid part again changes nothing.
    EXPECT_LT((without_rigid_part(points, d) - d).cwiseAbs().maxCoeff(), 1e-18);
  }
}

}  // namespace
}  // namespace hexatwist
