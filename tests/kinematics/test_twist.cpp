// SPDX-License-Identifier: BSD-3-Clause
// Twist (passive rotation): signed, matches an independent joint-chain computation, correct
// symmetries, analytic Jacobian, continuity.
#include "support.hpp"

namespace hexatwist::test {
namespace {

// Measured worst difference to the joint chain: 3.1e-15 rad (issue bound 1e-12); 10x margin.
constexpr double kChainTol = 3e-14;

void expect_twist_matches_chain(const Model& model, const Pose& pose) {
  LegState st;
  ASSERT_EQ(inverse_kinematics(model, pose, st), Status::Ok);
  Vector6d dtheta;
  ASSERT_EQ(twist(model, st, dtheta), Status::Ok);
  for (int i = 0; i < kLegs; ++i) {
    const auto chain = twist_by_joint_chain(model, st, i);
    ASSERT_TRUE(chain.has_value()) << "relative rotation not about the leg, leg " << i + 1 << " pose " << str(pose);
    EXPECT_NEAR(dtheta[i], *chain, kChainTol) << "leg " << i + 1 << " pose " << str(pose);
  }
}

TEST(Twist, MatchesJointChainOnSeedPlatform) {
  std::mt19937_64 rng(kSeed);
  for (int n = 0; n < 2000; ++n)
    expect_twist_matches_chain(seed_model(), random_valid_pose(seed_model(), rng, 0.5, deg2rad(30)));
}

TEST(Twist, MatchesJointChainOnRandomAsymmetricPlatforms) {
  std::mt19937_64 rng(kSeed + 1);
  for (int m = 0; m < 50; ++m) {
    const Model model = random_platform(rng);
    for (int n = 0; n < 40; ++n) expect_twist_matches_chain(model, random_valid_pose(model, rng, 0.3, deg2rad(25)));
  }
}

TEST(Twist, IsZeroAtHome) {
  LegState st;
  ASSERT_EQ(inverse_kinematics(seed_model(), Pose{}, st), Status::Ok);
  Vector6d dtheta;
  ASSERT_EQ(twist(seed_model(), st, dtheta), Status::Ok);
  EXPECT_LT(dtheta.cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Twist, AbsoluteAngleAtHomeIsSeventyDegreesAlternatingInSign) {
  // notes §3: about +-70.6 deg at home on the seed platform, mirror legs opposite.
  for (int i = 0; i < kLegs; ++i)
    EXPECT_NEAR(std::abs(rad2deg(seed_model().leg(i).theta_home)), 70.58, 0.01) << "leg " << i + 1;
  EXPECT_NEAR(seed_model().leg(0).theta_home, -seed_model().leg(1).theta_home, 1e-12);
}

TEST(Twist, HeaveTwistsMirrorLegsOppositely) {
  // The reason Eq. (9)'s arccos fails: for pure heave the two legs of a pair twist by equal and
  // opposite angles, which an unsigned angle cannot tell apart.
  Pose heave;
  heave.position.z() = 0.3;
  LegState st;
  ASSERT_EQ(inverse_kinematics(seed_model(), heave, st), Status::Ok);
  Vector6d dtheta;
  ASSERT_EQ(twist(seed_model(), st, dtheta), Status::Ok);
  for (int i = 0; i < kLegs; i += 2) {
    EXPECT_GT(std::abs(dtheta[i]), deg2rad(1.0));
    EXPECT_NEAR(dtheta[i], -dtheta[i + 1], 1e-13);
  }
}

TEST(Twist, MirrorPoseNegatesTwistOfMirrorLeg) {
  // The seed platform is symmetric about the x-z plane: legs (1,2), (3,6), (4,5) are mirror
  // images. Mirroring the pose mirrors the legs; the twist, a signed angle, changes sign.
  const std::array<int, kLegs> mirror{1, 0, 5, 4, 3, 2};
  std::mt19937_64 rng(kSeed + 2);
  for (int n = 0; n < 500; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.4, deg2rad(25));
    Pose q = p;
    q.position.y() = -p.position.y();
    q.rpy[0] = -p.rpy[0];
    q.rpy[2] = -p.rpy[2];
    LegState sp, sq;
    Vector6d tp, tq;
    ASSERT_EQ(inverse_kinematics(seed_model(), p, sp), Status::Ok);
    ASSERT_EQ(inverse_kinematics(seed_model(), q, sq), Status::Ok);
    ASSERT_EQ(twist(seed_model(), sp, tp), Status::Ok);
    ASSERT_EQ(twist(seed_model(), sq, tq), Status::Ok);
    for (int i = 0; i < kLegs; ++i) {
      EXPECT_NEAR(sq.length[mirror[i]], sp.length[i], 1e-13) << str(p);
      EXPECT_NEAR(tq[mirror[i]], -tp[i], 1e-12) << str(p);
    }
  }
}

TEST(Twist, ThreeFoldSymmetryPermutesLegs) {
  // Conjugating a pose by a 120 deg yaw maps the seed platform onto itself with leg i -> i+4.
  const Matrix3d Rz = Eigen::AngleAxisd(deg2rad(120), Vector3d::UnitZ()).toRotationMatrix();
  std::mt19937_64 rng(kSeed + 3);
  for (int n = 0; n < 500; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.4, deg2rad(25));
    const Placement xp = placement_from_pose(p);
    const Placement xq{Rz * xp.t, Rz * xp.R_BP * Rz.transpose()};
    LegState sp, sq;
    Vector6d tp, tq;
    ASSERT_EQ(inverse_kinematics(seed_model(), xp, sp), Status::Ok);
    ASSERT_EQ(inverse_kinematics(seed_model(), xq, sq), Status::Ok);
    ASSERT_EQ(twist(seed_model(), sp, tp), Status::Ok);
    ASSERT_EQ(twist(seed_model(), sq, tq), Status::Ok);
    for (int i = 0; i < kLegs; ++i) {
      EXPECT_NEAR(tq[(i + 4) % kLegs], tp[i], 1e-12) << "leg " << i + 1 << " pose " << str(p);
    }
  }
}

TEST(Twist, FlippingAnAxisSenseChangesNothing) {
  // jb and je are defined up to sign; the twist relative to home must not depend on that choice.
  ModelSpec spec = seed_model().spec();
  spec.legs[2].axis_base_B = -spec.legs[2].axis_base_B;
  spec.legs[4].axis_platform_P = -spec.legs[4].axis_platform_P;
  const Model flipped(spec);
  std::mt19937_64 rng(kSeed + 4);
  for (int n = 0; n < 200; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.4, deg2rad(25));
    LegState s1, s2;
    Vector6d t1, t2;
    ASSERT_EQ(inverse_kinematics(seed_model(), p, s1), Status::Ok);
    ASSERT_EQ(inverse_kinematics(flipped, p, s2), Status::Ok);
    ASSERT_EQ(twist(seed_model(), s1, t1), Status::Ok);
    ASSERT_EQ(twist(flipped, s2, t2), Status::Ok);
    EXPECT_LT((t1 - t2).cwiseAbs().maxCoeff(), 1e-13) << str(p);
  }
}

// Central differences of the twist under t += dt, R = exp(dw) R.
Matrix6d twist_jacobian_fd(const Model& model, const Placement& x, double h) {
  Matrix6d J;
  for (int k = 0; k < 6; ++k) {
    Vector6d d = Vector6d::Zero();
    d[k] = h;
    Placement xp{x.t + d.head<3>(), exp_so3(d.tail<3>()) * x.R_BP};
    Placement xm{x.t - d.head<3>(), exp_so3(-d.tail<3>()) * x.R_BP};
    LegState sp, sm;
    Vector6d tp, tm;
    EXPECT_EQ(inverse_kinematics(model, xp, sp), Status::Ok);
    EXPECT_EQ(inverse_kinematics(model, xm, sm), Status::Ok);
    EXPECT_EQ(twist(model, sp, tp), Status::Ok);
    EXPECT_EQ(twist(model, sm, tm), Status::Ok);
    J.col(k) = (tp - tm) / (2 * h);
  }
  return J;
}

TEST(Twist, JacobianMatchesCentralFiniteDifferences) {
  std::mt19937_64 rng(kSeed + 5);
  for (int m = 0; m < 10; ++m) {
    const Model model = m == 0 ? seed_model() : random_platform(rng);
    for (int n = 0; n < 20; ++n) {
      const Placement x = placement_from_pose(random_valid_pose(model, rng, 0.3, deg2rad(25)));
      LegState st;
      ASSERT_EQ(inverse_kinematics(model, x, st), Status::Ok);
      Matrix6d J;
      ASSERT_EQ(twist_jacobian(model, st, J), Status::Ok);
      const Matrix6d J_fd = twist_jacobian_fd(model, x, 1e-6);
      // Truncation O(h^2) and rounding O(eps/h): measured 1.9e-9; bound 10x that.
      EXPECT_LT((J - J_fd).cwiseAbs().maxCoeff(), 2e-8) << "model " << m << "\n" << J << "\nvs\n" << J_fd;
    }
  }
}

TEST(Twist, ALegAlongAFixedAxisIsReportedAsThatJointsSingularity) {
  // Put leg 3 exactly along its base axis, then along its platform axis: every twist function
  // must name that joint and never report Ok.
  LegState st;
  ASSERT_EQ(inverse_kinematics(seed_model(), Pose{}, st), Status::Ok);
  Vector6d v;
  Matrix6d J;
  LegState base = st;
  base.s_B.row(2) = seed_model().leg(2).axis_base_B.transpose();
  EXPECT_EQ(twist(seed_model(), base, v), Status::SingularBase);
  EXPECT_EQ(twist_absolute(seed_model(), base, v), Status::SingularBase);
  EXPECT_EQ(twist_jacobian(seed_model(), base, J), Status::SingularBase);
  LegState platform = st;
  platform.s_B.row(2) = -st.axis_platform_B.row(2);
  EXPECT_EQ(twist(seed_model(), platform, v), Status::SingularPlatform);
  EXPECT_EQ(twist_jacobian(seed_model(), platform, J), Status::SingularPlatform);
}

TEST(Twist, ContinuedTwistFollowsAMotionPastPi) {
  // A slow yaw sweep of 300 deg on a plain model (no limits involved in the twist itself): the
  // wrapped twist jumps by 2 pi somewhere, the continued one never jumps.
  Placement x;
  LegState st;
  Vector6d prev = Vector6d::Zero(), cont, wrapped;
  double max_abs = 0.0, max_step = 0.0;
  bool wrapped_jumped = false;
  Vector6d prev_wrapped = Vector6d::Zero();
  for (int k = 1; k <= 3000; ++k) {
    x.R_BP = Eigen::AngleAxisd(deg2rad(0.1 * k), Vector3d::UnitZ()).toRotationMatrix();
    ASSERT_EQ(inverse_kinematics(seed_model(), x, st), Status::Ok);
    ASSERT_EQ(twist_continued(seed_model(), st, prev, cont), Status::Ok) << "yaw " << 0.1 * k;
    ASSERT_EQ(twist(seed_model(), st, wrapped), Status::Ok);
    max_step = std::max(max_step, (cont - prev).cwiseAbs().maxCoeff());
    wrapped_jumped = wrapped_jumped || (wrapped - prev_wrapped).cwiseAbs().maxCoeff() > kPi;
    max_abs = std::max(max_abs, cont.cwiseAbs().maxCoeff());
    prev = cont;
    prev_wrapped = wrapped;
  }
  EXPECT_GT(max_abs, kPi);
  EXPECT_TRUE(wrapped_jumped);
  EXPECT_LT(max_step, deg2rad(2.0));
}

}  // namespace
}  // namespace hexatwist::test
