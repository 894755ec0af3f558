// SPDX-License-Identifier: BSD-3-Clause
// The legs' forces along a known motion (leg_forces.hpp), checked without their own derivation:
// zero at rest, the difference of the inverse dynamics' nut forces in motion and at rest, linear in
// the acceleration and quadratic in the velocity, a vertical acceleration acting on the platform as
// more gravity, and the trajectory's motion as the motor sizing takes it.
#include <gtest/gtest.h>

#include <random>

#include "hexatwist/dynamics/leg_forces.hpp"
#include "hexatwist/io/config.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "hexatwist/simulation/study.hpp"
#include "support.hpp"

namespace hexatwist {
namespace {
using namespace test;

Vector6d random_vector(std::mt19937_64& rng, double scale) {
  Vector6d v;
  for (int i = 0; i < 6; ++i) v[i] = uniform(rng, -scale, scale);
  return v;
}

TEST(LegForces, InertialForcesAreTheNutForcesInMotionLessThoseAtRest) {
  const Rig& rig = seed_rig();
  std::mt19937_64 rng(kSeed + 601);
  double worst = 0.0;
  for (int n = 0; n < 100; ++n) {
    PlatformMotion motion;
    motion.placement = placement_from_pose(random_valid_pose(rig.model(), rng, 0.3, deg2rad(20)));
    Vector6d force;
    ASSERT_EQ(inertial_leg_forces(rig, motion, force), Status::Ok);
    EXPECT_EQ(force, Vector6d::Zero()) << "exactly zero at rest";
    motion.velocity = random_vector(rng, 0.5);
    motion.acceleration = random_vector(rng, 3.0);
    ASSERT_EQ(inertial_leg_forces(rig, motion, force), Status::Ok);
    InverseDynamics moving, still;
    ASSERT_EQ(inverse_dynamics(rig, motion, moving), Status::Ok);
    PlatformMotion rest;
    rest.placement = motion.placement;
    ASSERT_EQ(inverse_dynamics(rig, rest, still), Status::Ok);
    const Vector6d difference = moving.screw_force - still.screw_force;
    worst = std::max(worst, (force - difference).cwiseAbs().maxCoeff() / difference.cwiseAbs().maxCoeff());
  }
  report("largest relative difference from screw_force in motion less at rest", worst);
  EXPECT_LT(worst, 1e-12);
}

TEST(LegForces, LinearInTheAccelerationAndQuadraticInTheVelocity) {
  const Rig& rig = seed_rig();
  std::mt19937_64 rng(kSeed + 602);
  for (int n = 0; n < 50; ++n) {
    PlatformMotion a, b;
    a.placement = b.placement = placement_from_pose(random_valid_pose(rig.model(), rng, 0.3, deg2rad(20)));
    a.acceleration = random_vector(rng, 3.0);
    b.acceleration = 2.0 * a.acceleration;
    Vector6d fa, fb;
    ASSERT_EQ(inertial_leg_forces(rig, a, fa), Status::Ok);
    ASSERT_EQ(inertial_leg_forces(rig, b, fb), Status::Ok);
    EXPECT_LT((fb - 2.0 * fa).norm(), 1e-10 * fa.norm()) << "acceleration alone: linear";
    a.acceleration = b.acceleration = Vector6d::Zero();
    a.velocity = random_vector(rng, 0.5);
    b.velocity = 2.0 * a.velocity;
    ASSERT_EQ(inertial_leg_forces(rig, a, fa), Status::Ok);
    ASSERT_EQ(inertial_leg_forces(rig, b, fb), Status::Ok);
    EXPECT_GT(fa.norm(), 0.0);
    EXPECT_LT((fb - 4.0 * fa).norm(), 1e-10 * fa.norm()) << "velocity alone: quadratic (velocity products)";
  }
}

TEST(LegForces, AnUpwardAccelerationAtHomeActsAsMoreGravity) {
  // Accelerating the platform up by a tenth of g loads the legs as gravity does, a tenth as much:
  // exactly so for the platform and payload, which translate; the legs' bodies turn as well, which
  // the measured difference is (1.5e-2 of the force on the seed).
  const Rig& rig = seed_rig();
  const double g = 9.80665;
  PlatformMotion up;
  up.acceleration[2] = 0.1 * g;
  Vector6d inertial;
  ASSERT_EQ(inertial_leg_forces(rig, up, inertial), Status::Ok);
  const Vector6d& at_rest = rig.model().reference_force();
  const double relative = (inertial - 0.1 * at_rest).cwiseAbs().maxCoeff() / (0.1 * at_rest).cwiseAbs().maxCoeff();
  report("relative difference from a tenth of the static forces", relative);
  EXPECT_TRUE((inertial.array() < 0.0).all()) << "pushing up compresses the legs";
  EXPECT_LT(relative, 5e-2);
}

TEST(LegForces, AlongATrajectoryTheStaticLoadPlusTheMotionsShareAsTheMotorSizingTakesIt) {
  const Rig& rig = seed_rig();
  const Trajectory trajectory = test_trajectory(StudySpec{}, study_test(StudySpec{}, "Lx"), 0.01);
  std::vector<Vector6d> force;
  std::size_t at = 99;
  ASSERT_EQ(trajectory_leg_forces(rig, trajectory, force, at), Status::Ok);
  EXPECT_EQ(at, 0u);
  ASSERT_EQ(force.size(), trajectory.poses.size());
  double largest = 0.0;
  for (std::size_t k = 0; k < trajectory.poses.size(); ++k) {
    const PlatformMotion motion = trajectory_motion(trajectory, k);
    LegState legs;
    ASSERT_EQ(inverse_kinematics(rig.model(), motion.placement, legs), Status::Ok);
    Vector6d still;
    ASSERT_EQ(static_leg_forces(rig.model(), rig.model().spec().static_load, legs, still), Status::Ok);
    if (k == 0 || k + 1 == trajectory.poses.size()) {
      EXPECT_EQ(force[k], still) << "the test starts and ends at rest";
    }
    largest = std::max(largest, (force[k] - still).cwiseAbs().maxCoeff());
    // The motion by the differences the motor sizing takes (motor_sizing.cpp).
    if (k > 0 && k + 1 < trajectory.poses.size()) {
      const Vector6d rate =
          (trajectory.poses[k + 1].to_vector() - trajectory.poses[k - 1].to_vector()) / (2.0 * trajectory.dt);
      EXPECT_LT((motion.velocity.head<3>() - rate.head<3>()).norm(), 1e-12);
    }
  }
  report("largest inertial share along the Lx test [N]", largest);
  EXPECT_GT(largest, 10.0) << "the sweep's accelerations load the legs";
  // Too short a trajectory is refused with nothing written.
  Trajectory one = trajectory;
  one.poses.resize(1);
  EXPECT_EQ(trajectory_leg_forces(rig, one, force, at), Status::InvalidArgument);
  EXPECT_TRUE(force.empty());
}

}  // namespace
}  // namespace hexatwist
