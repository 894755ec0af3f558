// Limits: stroke, bend and U-joint singularity, each reported with the right leg and value.
#include "support.hpp"

namespace hexatwist::test {
namespace {

Status check(const Model& model, const Pose& p, LimitReport& r) {
  LegState st;
  EXPECT_EQ(inverse_kinematics(model, p, st), Status::Ok);
  return check_limits(model, st, r);
}

TEST(Limits, SeedTestExtremesAreInside) {
  // The seed's four tests at their extremes (notes §1) must pass the default limits.
  for (const Vector6d& q : {(Vector6d() << 0.5, 0, 0, 0, 0, 0).finished(), (Vector6d() << -0.5, 0, 0, 0, 0, 0).finished(),
                           (Vector6d() << 0, 0, 0.5, 0, 0, 0).finished(), (Vector6d() << 0, 0, -0.5, 0, 0, 0).finished(),
                           (Vector6d() << 0, 0, 0, 0, deg2rad(30), 0).finished(), (Vector6d() << 0, 0, 0, 0, -deg2rad(30), 0).finished(),
                           (Vector6d() << 0, 0, 0, 0, 0, deg2rad(30)).finished(), (Vector6d() << 0, 0, 0, 0, 0, -deg2rad(30)).finished()}) {
    LimitReport r;
    EXPECT_EQ(check(seed_model(), Pose::from_vector(q), r), Status::Ok) << q.transpose();
  }
}

TEST(Limits, StrokeViolationsNameLegAndValue) {
  LimitReport r;
  Pose up;
  up.position.z() = 0.8;
  EXPECT_EQ(check(seed_model(), up, r), Status::StrokeAboveMax);
  EXPECT_EQ(r.leg, 0);
  EXPECT_GT(r.value, 2.45);
  EXPECT_EQ(r.bound, 2.45);
  Pose down;
  down.position.z() = -0.9;
  EXPECT_EQ(check(seed_model(), down, r), Status::StrokeBelowMin);
  EXPECT_LT(r.value, 1.40);
  // A sideways move stretches some legs only: the first long one is reported.
  Pose side;
  side.position.x() = -0.9;
  ASSERT_NE(check(seed_model(), side, r), Status::Ok);
  LegState st;
  ASSERT_EQ(inverse_kinematics(seed_model(), side, st), Status::Ok);
  EXPECT_NEAR(r.value, st.length[r.leg], 1e-15);
}

TEST(Limits, BendViolationMatchesBendAngles) {
  ModelSpec spec = seed_model().spec();
  spec.limits.bend_max = deg2rad(20);
  const Model tight(spec);
  Pose p;
  p.rpy[1] = -deg2rad(25);
  LimitReport r;
  const Status s = check(tight, p, r);
  ASSERT_TRUE(s == Status::BendBase || s == Status::BendPlatform) << to_string(s);
  LegState st;
  ASSERT_EQ(inverse_kinematics(tight, p, st), Status::Ok);
  Vector6d bb, bp;
  bend_angles(tight, st, bb, bp);
  EXPECT_NEAR(r.value, s == Status::BendBase ? bb[r.leg] : bp[r.leg], 1e-12);
  EXPECT_GT(r.value, r.bound);
  // Every earlier leg is inside the bend limit.
  for (int i = 0; i < r.leg; ++i) EXPECT_LE(std::max(bb[i], bp[i]), spec.limits.bend_max);
}

TEST(Limits, SingularityMarginIsReportedForTheRightJoint) {
  // Raise the margin to just below the home leg-axis angle and look for poses that close it.
  ModelSpec spec = seed_model().spec();
  double home_angle = kPi;
  for (const Leg& leg : seed_model().legs())
    for (const Vector3d& axis : {leg.axis_base_B, leg.axis_platform_P})
      home_angle = std::min(home_angle, std::atan2(leg.s_home_B.cross(axis).norm(), std::abs(leg.s_home_B.dot(axis))));
  spec.limits.singularity_margin = home_angle - deg2rad(1);
  spec.limits.bend_max = deg2rad(90);
  spec.limits.length_min = 0.5;
  spec.limits.length_max = 4.0;
  const Model model(spec);
  std::mt19937_64 rng(kSeed + 50);
  int found = 0;
  for (int n = 0; n < 2000; ++n) {
    const Pose p = random_pose(rng, 0.3, deg2rad(20));
    LimitReport r;
    const Status s = check(model, p, r);
    if (s != Status::SingularBase && s != Status::SingularPlatform) continue;
    ++found;
    LegState st;
    ASSERT_EQ(inverse_kinematics(model, p, st), Status::Ok);
    const Vector3d axis = s == Status::SingularBase ? model.leg(r.leg).axis_base_B
                                                    : Vector3d(st.axis_platform_B.row(r.leg).transpose());
    EXPECT_NEAR(std::sin(r.value), st.s_B.row(r.leg).transpose().cross(axis).norm(), 1e-12);
    EXPECT_LT(r.value, r.bound);
  }
  EXPECT_GT(found, 10);
}

TEST(Limits, CommandStrokeCheckNamesTheLeg) {
  Vector6d cmd = seed_model().length_home();
  LimitReport r;
  EXPECT_EQ(check_stroke(seed_model(), cmd, r), Status::Ok);
  cmd[4] = 2.5;
  EXPECT_EQ(check_stroke(seed_model(), cmd, r), Status::StrokeAboveMax);
  EXPECT_EQ(r.leg, 4);
  cmd[2] = std::nan("");
  EXPECT_EQ(check_stroke(seed_model(), cmd, r), Status::NonFiniteInput);
  EXPECT_EQ(r.leg, 2);
}

}  // namespace
}  // namespace hexatwist::test
