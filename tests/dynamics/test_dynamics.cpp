// SPDX-License-Identifier: BSD-3-Clause
// Leg-space load: checked against energy computed without any Jacobian (finite differences of the
// pose that forward kinematics gives for perturbed leg lengths).
#include <gtest/gtest.h>

#include "hexatwist/dynamics/dynamics.hpp"
#include "hexatwist/io/config.hpp"
#include "support.hpp"

#include <Eigen/Eigenvalues>

namespace hexatwist {
namespace {
using namespace test;

struct Frame {
  Vector3d com;  // centre of mass [m, B]
  Matrix3d R;
};

// The pose (as centre of mass and rotation) for leg lengths m of `kind`, by forward kinematics.
Frame frame_for(const Model& model, const LoadSpec& load, const Vector6d& m, LengthKind kind, const Placement& guess) {
  FkResult fk;
  EXPECT_EQ(forward_kinematics(model, m, kind, guess, fk), Status::Ok);
  const Vector3d pivot = model.pivot_home_B() + fk.placement.t;
  return {pivot + fk.placement.R_BP * (load.center_of_mass_P - model.spec().pivot_P), fk.placement.R_BP};
}

// The leg lengths of `kind` at the state `legs`: geometric, or motor-side (twist subtracted).
Vector6d lengths_of(const Model& model, const LegState& legs, LengthKind kind) {
  Vector6d m = legs.length;
  if (kind == LengthKind::Motor) {
    Vector6d dtheta;
    EXPECT_EQ(twist(model, legs, dtheta), Status::Ok);
    m -= model.geometry().twist_gain.cwiseProduct(dtheta);
  }
  return m;
}

class DynamicsTest : public ::testing::TestWithParam<LengthKind> {};

// Gravity: the force along each leg is minus the derivative of the potential energy m g z_com
// with respect to that leg's length (virtual work), by central differences through FK.
TEST_P(DynamicsTest, GravityIsMinusTheGradientOfThePotential) {
  const Model& model = seed_model();
  const LoadSpec load;
  const LengthKind kind = GetParam();
  std::mt19937_64 rng(kSeed);
  double worst = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = random_valid_pose(model, rng, 0.3, deg2rad(20));
    const Placement x = placement_from_pose(pose);
    LegState legs;
    ASSERT_EQ(inverse_kinematics(model, x, legs), Status::Ok);
    LegDynamics dyn;
    ASSERT_EQ(leg_dynamics(model, load, legs, kind, dyn), Status::Ok);
    const Vector6d m = lengths_of(model, legs, kind);
    const double h = 1e-6;
    for (int i = 0; i < kLegs; ++i) {
      Vector6d mp = m, mm = m;
      mp[i] += h;
      mm[i] -= h;
      const double dV = load.mass * load.gravity *
                        (frame_for(model, load, mp, kind, x).com.z() - frame_for(model, load, mm, kind, x).com.z()) /
                        (2 * h);
      worst = std::max(worst, std::abs(-dV - dyn.gravity[i]) / (load.mass * load.gravity));
    }
  }
  EXPECT_LT(worst, 1e-6);  // measured ~5e-8 (relative to the weight)
}

// Mass: for a leg-rate vector mdot, 1/2 mdot^T M_m mdot equals the kinetic energy of the rigid
// load moving with the pose rates that FK gives (centre-of-mass velocity and angular velocity by
// central differences).
TEST_P(DynamicsTest, MassMatrixGivesTheKineticEnergy) {
  const Model& model = seed_model();
  LoadSpec load;
  load.center_of_mass_P = Vector3d(0.1, -0.05, 0.2);
  load.inertia = Vector3d(400, 600, 900);
  const LengthKind kind = GetParam();
  std::mt19937_64 rng(kSeed + 1);
  double worst = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = random_valid_pose(model, rng, 0.3, deg2rad(20));
    const Placement x = placement_from_pose(pose);
    LegState legs;
    ASSERT_EQ(inverse_kinematics(model, x, legs), Status::Ok);
    LegDynamics dyn;
    ASSERT_EQ(leg_dynamics(model, load, legs, kind, dyn), Status::Ok);
    const Vector6d m = lengths_of(model, legs, kind);
    Vector6d mdot;
    for (int i = 0; i < kLegs; ++i) mdot[i] = uniform(rng, -0.2, 0.2);
    const double h = 1e-6;
    const Frame a = frame_for(model, load, m + h * mdot, kind, x);
    const Frame b = frame_for(model, load, m - h * mdot, kind, x);
    const Vector3d v = (a.com - b.com) / (2 * h);
    const Eigen::AngleAxisd rel(a.R * b.R.transpose());
    const Vector3d w = rel.angle() * rel.axis() / (2 * h);
    const Matrix3d I_B = x.R_BP * load.inertia.asDiagonal() * x.R_BP.transpose();
    const double T_direct = 0.5 * load.mass * v.squaredNorm() + 0.5 * w.dot(I_B * w);
    const double T_leg = 0.5 * mdot.dot(dyn.mass * mdot);
    worst = std::max(worst, std::abs(T_leg - T_direct) / T_direct);
  }
  EXPECT_LT(worst, 1e-6);  // measured ~1e-8
}

INSTANTIATE_TEST_SUITE_P(Kinds, DynamicsTest, ::testing::Values(LengthKind::Geometric, LengthKind::Motor));

// At home the platform is symmetric: every leg carries the same share of the weight, and the
// vertical components of the six leg forces add up to the weight.
TEST(Dynamics, HomeLoadIsSharedEquallyAndBalancesTheWeight) {
  const Model& model = seed_model();
  LoadSpec load;
  load.center_of_mass_P = Vector3d::Zero();
  LegState legs;
  ASSERT_EQ(inverse_kinematics(model, Placement{}, legs), Status::Ok);
  LegDynamics dyn;
  ASSERT_EQ(leg_dynamics(model, load, legs, LengthKind::Geometric, dyn), Status::Ok);
  const double W = load.mass * load.gravity;
  double vertical = 0.0;
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_NEAR(dyn.gravity[i], dyn.gravity[0], 1e-9 * W);
    vertical += -dyn.gravity[i] * legs.s_B(i, 2);  // a leg pushes the platform along +s with -F
  }
  EXPECT_NEAR(vertical, W, 1e-9 * W);
  EXPECT_LT(dyn.gravity[0], 0.0);  // the legs are compressed
}

TEST(Dynamics, MassMatrixIsSymmetricPositiveDefinite) {
  const Model& model = seed_model();
  Matrix6d M;
  platform_mass_matrix(model, LoadSpec{}, rotation_from_rpy(Vector3d(0.2, -0.3, 0.5)), M);
  EXPECT_LT((M - M.transpose()).norm(), 1e-12 * M.norm());
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(M);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
}

}  // namespace
}  // namespace hexatwist
