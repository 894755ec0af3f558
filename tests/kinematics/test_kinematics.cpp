// SPDX-License-Identifier: BSD-3-Clause
// Inverse kinematics (Eq. 1-4): the seed geometry as read in the notes, symmetry, Jacobian, pivot.
#include "support.hpp"

namespace hexatwist::test {
namespace {

TEST(Kinematics, SeedLegsAreAllOnePointNineOneMetresTiltedThirtySevenDegrees) {
  // notes §1: 1.910 m, 37.7 deg from vertical; leg 1 by hand: base joint at 60 deg minus db/2
  // along the tangent, platform joint at (Ra, +da/2).
  const double c = std::cos(deg2rad(60)), s = std::sin(deg2rad(60));
  const Vector3d b1 = 1.5 * Vector3d(c, s, 0) - 0.15 * Vector3d(-s, c, 0);
  const Vector3d p1(1.2, 0.1, 1.511);
  LegState st;
  ASSERT_EQ(inverse_kinematics(seed_model(), Pose{}, st), Status::Ok);
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_NEAR(st.length[i], (p1 - b1).norm(), 1e-12) << "leg " << i + 1;
    EXPECT_NEAR(rad2deg(std::acos(st.s_B(i, 2))), 37.7, 0.05);
  }
  EXPECT_NEAR(st.length[0], 1.910, 5e-4);
}

TEST(Kinematics, SeedAxesAreThoseOfEquationSix) {
  const double r = std::sqrt(3.0) / 2.0;
  const std::array<Vector3d, kLegs> ja{Vector3d(-r, 0.5, 0), Vector3d(r, 0.5, 0), Vector3d(r, 0.5, 0),
                                       Vector3d(0, -1, 0),   Vector3d(0, -1, 0),  Vector3d(-r, 0.5, 0)};
  const std::array<Vector3d, kLegs> jd{Vector3d(0, 1, 0),    Vector3d(0, 1, 0),     Vector3d(r, -0.5, 0),
                                       Vector3d(r, -0.5, 0), Vector3d(-r, -0.5, 0), Vector3d(-r, -0.5, 0)};
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_LT((seed_model().leg(i).axis_base_B - ja[static_cast<std::size_t>(i)]).norm(), 1e-15) << "leg " << i + 1;
    EXPECT_LT((seed_model().leg(i).axis_platform_P - jd[static_cast<std::size_t>(i)]).norm(), 1e-15) << "leg " << i + 1;
  }
}

TEST(Kinematics, ThreeFoldSymmetryPermutesLegLengths) {
  const Matrix3d Rz = Eigen::AngleAxisd(deg2rad(120), Vector3d::UnitZ()).toRotationMatrix();
  std::mt19937_64 rng(kSeed + 40);
  for (int n = 0; n < 1000; ++n) {
    const Placement x = placement_from_pose(random_pose(rng, 0.5, deg2rad(30)));
    LegState a, b;
    ASSERT_EQ(inverse_kinematics(seed_model(), x, a), Status::Ok);
    ASSERT_EQ(inverse_kinematics(seed_model(), Placement{Rz * x.t, Rz * x.R_BP * Rz.transpose()}, b), Status::Ok);
    for (int i = 0; i < kLegs; ++i) EXPECT_NEAR(b.length[(i + 4) % kLegs], a.length[i], 1e-13);
  }
}

TEST(Kinematics, LengthJacobianMatchesCentralFiniteDifferences) {
  std::mt19937_64 rng(kSeed + 41);
  const double h = 1e-6;
  for (int m = 0; m < 10; ++m) {
    const Model model = m == 0 ? seed_model() : random_platform(rng);
    for (int n = 0; n < 20; ++n) {
      const Placement x = placement_from_pose(random_valid_pose(model, rng, 0.3, deg2rad(25)));
      LegState st, sp, sm;
      ASSERT_EQ(inverse_kinematics(model, x, st), Status::Ok);
      Matrix6d J, J_fd;
      length_jacobian(st, J);
      for (int k = 0; k < 6; ++k) {
        Vector6d d = Vector6d::Zero();
        d[k] = h;
        ASSERT_EQ(inverse_kinematics(model, Placement{x.t + d.head<3>(), exp_so3(d.tail<3>()) * x.R_BP}, sp),
                  Status::Ok);
        ASSERT_EQ(inverse_kinematics(model, Placement{x.t - d.head<3>(), exp_so3(-d.tail<3>()) * x.R_BP}, sm),
                  Status::Ok);
        J_fd.col(k) = (sp.length - sm.length) / (2 * h);
      }
      EXPECT_LT((J - J_fd).cwiseAbs().maxCoeff(), 5e-9) << J << "\nvs\n" << J_fd;  // measured 4.3e-10
    }
  }
}

TEST(Kinematics, RotationsActAboutThePivot) {
  // With the pivot at the observation point, a pure rotation leaves that point where it is.
  ModelSpec spec = seed_model().spec();
  spec.pivot_P = spec.observation_P;
  const Model pivoted(spec);
  Pose p;
  p.rpy = Vector3d(0.1, -0.2, 0.3);
  const Vector3d A = spec.observation_P;
  const Vector3d home_A = platform_point_B(pivoted, Placement{}, A);
  EXPECT_LT((platform_point_B(pivoted, placement_from_pose(p), A) - home_A).norm(), 1e-15);
  EXPECT_LT((home_A - Vector3d(1.2, 0, 1.511)).norm(), 1e-15);
  // ... and the legs reach the rotated joints: compare with the centre-pivot model moved back.
  LegState a, b;
  ASSERT_EQ(inverse_kinematics(pivoted, p, a), Status::Ok);
  Pose q = p;
  q.position = A - rotation_from_rpy(p.rpy) * A;  // same motion written about the centre
  ASSERT_EQ(inverse_kinematics(seed_model(), q, b), Status::Ok);
  EXPECT_LT((a.length - b.length).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(Kinematics, NonFinitePoseIsRejected) {
  Pose p;
  p.rpy[0] = INFINITY;
  LegState st;
  EXPECT_EQ(inverse_kinematics(seed_model(), p, st), Status::NonFiniteInput);
}

}  // namespace
}  // namespace hexatwist::test
