// The real platform against the model (parameter_errors.hpp): each error changes what it should
// and nothing else, and the real motor lengths invert to the nominal reading.
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
  EXPECT_EQ(real.spec().observation_P, nominal.spec().observation_P);
  Vector6d m;
  m << 1.7, 1.8, 1.9, 2.0, 2.1, 2.2;
  Vector6d out;
  real_motor_lengths(nominal, ParameterErrors{}, m, out);
  EXPECT_EQ(out, m);
}

TEST(ParameterErrors, EachErrorChangesItsOwnParameter) {
  const Model& nominal = seed_model();
  ParameterErrors e;
  e.lead_error = 0.05;
  const Model longer = real_model(nominal, e);
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_DOUBLE_EQ(longer.leg(i).lead, 1.05 * nominal.leg(i).lead);
    EXPECT_DOUBLE_EQ(longer.leg(i).twist_gain, 1.05 * nominal.leg(i).twist_gain);  // Eq. (10) scales with the lead
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
  e.lead_error = -1.5;
  EXPECT_THROW((void)real_model(nominal, e), Error);  // a negative lead
}

TEST(ParameterErrors, RealMotorLengthsScaleTheTravelAndShiftTheZero) {
  const Model& nominal = seed_model();
  ParameterErrors e;
  e.lead_error = 0.02;
  e.zero_offset << 1e-3, -1e-3, 0.5e-3, 0, 2e-4, -7e-4;
  // At the home reading, only the offsets; 0.1 m of nominal travel is 0.102 m of real travel.
  Vector6d out;
  real_motor_lengths(nominal, e, nominal.length_home(), out);
  EXPECT_LT((out - nominal.length_home() - e.zero_offset).cwiseAbs().maxCoeff(), 1e-15);
  real_motor_lengths(nominal, e, nominal.length_home() + Vector6d::Constant(0.1), out);
  EXPECT_LT((out - nominal.length_home() - e.zero_offset - Vector6d::Constant(0.102)).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ParameterErrors, TheRealPlatformRunsWhereItsOwnCommandsSay) {
  // A controller that knew the real platform would command it exactly: its compensated command
  // (real model), read back through the errors as a nominal reading, then mapped forward again by
  // real_motor_lengths and the real model's twist-aware FK, returns the pose.
  const Model& nominal = seed_model();
  ParameterErrors e;
  e.lead_error = 0.03;
  e.flip_twist_sign = true;
  e.zero_offset << 1e-3, -1e-3, 0.5e-3, 0, 2e-4, -7e-4;
  const Model real = real_model(nominal, e);
  std::mt19937_64 rng(test::kSeed + 501);
  double worst = 0.0;
  for (int n = 0; n < test::stress(200); ++n) {
    const Pose pose = test::random_valid_pose(real, rng, 0.2, deg2rad(15));
    Vector6d command, reading, motor;
    LimitReport limit;
    ASSERT_EQ(motor_commands(real, pose, Strategy::Compensated, command, limit), Status::Ok);
    reading = nominal.length_home() + (command - nominal.length_home() - e.zero_offset) / (1.0 + e.lead_error);
    real_motor_lengths(nominal, e, reading, motor);
    FkResult fk;
    ASSERT_EQ(forward_kinematics(real, motor, LengthKind::Motor, Placement{}, fk), Status::Ok);
    worst = std::max(worst, (fk.pose.to_vector() - pose.to_vector()).cwiseAbs().maxCoeff());
  }
  test::report("pose error [m, rad]", worst);
  EXPECT_LT(worst, 1e-11);
}

}  // namespace
}  // namespace hexatwist
