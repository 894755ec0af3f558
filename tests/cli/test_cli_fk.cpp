// SPDX-License-Identifier: BSD-3-Clause
// hexatwist fk: the pose of six leg lengths.
#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

// ---- fk --------------------------------------------------------------------------------------

TEST(Cli, FkOfCompensatedCommandsWithMotorReturnsTheIkPose) {
  // ik takes degrees, fk's JSON answers in radians.
  const std::vector<double> pose_deg{0.05, -0.03, 0.12, 4.0, -3.0, 7.0};
  const std::vector<double> pose{0.05, -0.03, 0.12, deg2rad(4.0), deg2rad(-3.0), deg2rad(7.0)};
  const Outcome ik = run({"ik", "--pose=" + numbers(pose_deg), "--json"});
  ASSERT_EQ(ik.code, 0) << ik.err;
  const std::vector<double> commands = leg_values(json(ik), "command_compensated");
  const Outcome fk = run({"fk", "--lengths=" + numbers(commands), "--motor", "--json"});
  ASSERT_EQ(fk.code, 0) << fk.err;
  const YAML::Node j = json(fk);
  EXPECT_EQ(j["status"].as<std::string>(), "ok");
  EXPECT_EQ(j["lengths_kind"].as<std::string>(), "motor");
  ASSERT_EQ(j["pose"].size(), 6u);
  // FK stops at a 1e-12 m residual: measured worst pose error 1.0e-12 over 10^4 poses; 10x.
  for (std::size_t k = 0; k < 6; ++k) EXPECT_NEAR(j["pose"][k].as<double>(), pose[k], 1e-11) << "component " << k;
}

TEST(Cli, FkWithoutMotorOnMotorCommandsGivesAnotherPose) {
  // The same numbers read as geometric lengths miss the twist: the pose is off by far more
  // than the solver's accuracy.
  const Outcome ik = run({"ik", "--pose=0.05,-0.03,0.12,4,-3,7", "--json"});
  ASSERT_EQ(ik.code, 0) << ik.err;
  const std::string lengths = "--lengths=" + numbers(leg_values(json(ik), "command_compensated"));
  const Outcome motor = run({"fk", lengths, "--motor", "--json"});
  const Outcome geometric = run({"fk", lengths, "--json"});
  ASSERT_EQ(motor.code, 0) << motor.err;
  ASSERT_EQ(geometric.code, 0) << geometric.err;
  EXPECT_EQ(json(geometric)["lengths_kind"].as<std::string>(), "geometric");
  double diff = 0.0;
  for (std::size_t k = 0; k < 6; ++k)
    diff = std::max(diff, std::abs(json(motor)["pose"][k].as<double>() - json(geometric)["pose"][k].as<double>()));
  EXPECT_GT(diff, 1e-5);  // measured 3.5e-4
}

TEST(Cli, FkOfIkLengthsReturnsThePose) {
  const Outcome ik = run({"ik", "--pose=-0.04,0.06,-0.05,-2,5,-8", "--json"});
  ASSERT_EQ(ik.code, 0) << ik.err;
  const Outcome fk = run({"fk", "--lengths=" + numbers(leg_values(json(ik), "length")), "--json"});
  ASSERT_EQ(fk.code, 0) << fk.err;
  const std::vector<double> pose{-0.04, 0.06, -0.05, deg2rad(-2), deg2rad(5), deg2rad(-8)};
  // FK stops at a 1e-12 m residual: measured worst pose error 1.0e-12 over 10^4 poses; 10x.
  for (std::size_t k = 0; k < 6; ++k) EXPECT_NEAR(json(fk)["pose"][k].as<double>(), pose[k], 1e-11) << k;
}

TEST(Cli, FkWithImpossibleLengthsFailsWithExitThree) {
  const Outcome r = run({"fk", "--lengths=1,1,1,1,1,1", "--json"});
  expect_error(r, 3, {"forward kinematics failed"});
  EXPECT_TRUE(r.err.find("no_convergence") != std::string::npos || r.err.find("singular") != std::string::npos)
      << r.err;
  const YAML::Node j = json(r);
  const std::string status = j["status"].as<std::string>();
  EXPECT_TRUE(status == "no_convergence" || status.rfind("singular", 0) == 0) << status;
  EXPECT_TRUE(j["pose"].IsNull());
}

TEST(Cli, FkOfLengthsOnTheStrokeEndsIsInsideTheLimits) {
  // Every leg typed on an end of the stroke (1.40 / 2.45 m): FK recomputes 1.4 as
  // 1.3999999999999997; on a bound is inside it (limits.hpp).
  const Outcome r = run({"fk", "--lengths=1.4,2.45,1.4,2.45,1.4,2.45", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(json(r)["status"].as<std::string>(), "ok");
  EXPECT_TRUE(json(r)["limit"].IsNull());
  const Outcome text = run({"fk", "--lengths=1.4,2.45,1.4,2.45,1.4,2.45"});
  EXPECT_EQ(text.code, 0) << text.err;
}

TEST(Cli, FkRejectsFiveLengths) { expect_error(run({"fk", "--lengths=1.9,1.9,1.9,1.9,1.9"}), 2, {"--lengths", "6"}); }

TEST(Cli, FkRejectsLengthsThatAreNotLengths) {
  expect_error(run({"fk", "--lengths=1.9,1.9,-1.9,1.9,1.9,1.9"}), 2, {"--lengths", "value 3", "> 0"});
  expect_error(run({"fk", "--lengths=0,0,0,0,0,0", "--motor"}), 2, {"--lengths", "value 1"});
}

}  // namespace
