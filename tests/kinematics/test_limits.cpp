// SPDX-License-Identifier: BSD-3-Clause
// Limits: stroke, bend, U-joint and platform singularity, each reported with the right leg and value.
#include <fmt/format.h>
#include <Eigen/LU>
#include <Eigen/SVD>

#include <iomanip>

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
  for (const Vector6d& q :
       {(Vector6d() << 0.5, 0, 0, 0, 0, 0).finished(), (Vector6d() << -0.5, 0, 0, 0, 0, 0).finished(),
        (Vector6d() << 0, 0, 0.5, 0, 0, 0).finished(), (Vector6d() << 0, 0, -0.5, 0, 0, 0).finished(),
        (Vector6d() << 0, 0, 0, 0, deg2rad(30), 0).finished(), (Vector6d() << 0, 0, 0, 0, -deg2rad(30), 0).finished(),
        (Vector6d() << 0, 0, 0, 0, 0, deg2rad(30)).finished(),
        (Vector6d() << 0, 0, 0, 0, 0, -deg2rad(30)).finished()}) {
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

TEST(Limits, ADescriptionNamesTheLegFromOneTheKeyAndDigitsThatTellValueFromBound) {
  LimitReport r;
  Pose up;
  up.position.z() = 0.8;
  ASSERT_EQ(check(seed_model(), up, r), Status::StrokeAboveMax);
  const std::string text = describe(r);
  EXPECT_EQ(text.rfind(fmt::format("leg {}: length ", r.leg + 1), 0), 0U) << text;
  EXPECT_NE(text.find("above the maximum 2.450000 m (limits.length_max)"), std::string::npos) << text;
  // A value a hair past its bound gets the digits that show it: never "2.450000 above 2.450000".
  r.value = r.bound + 3e-8;
  EXPECT_NE(describe(r).find("2.45000003 m is above the maximum 2.45000000 m"), std::string::npos) << describe(r);
  r.value = r.bound + 1e-12;  // within 10 nm: at the limit
  EXPECT_NE(describe(r).find("at the maximum 2.450000 m"), std::string::npos) << describe(r);
  // The whole platform's limit has no leg; Ok is "ok".
  LimitReport condition;
  condition.status = Status::PlatformSingularity;
  condition.value = 61.0;
  condition.bound = 50.0;
  EXPECT_EQ(describe(condition).rfind("the platform is near a singularity", 0), 0U) << describe(condition);
  EXPECT_NE(describe(condition).find("(limits.jacobian_condition_max)"), std::string::npos);
  EXPECT_EQ(describe(LimitReport{}), "ok");
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
    const Vector3d axis =
        s == Status::SingularBase ? model.leg(r.leg).axis_base_B : Vector3d(st.axis_platform_B.row(r.leg).transpose());
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

// ---- boundaries: on a limit is inside it (limits.hpp, kLimitTolerance) ------------------------

// What every path decides for `p`: the scalar check after inverse kinematics, and the real-time
// path (vectorised lanes, then the naming fallback) for the conventional command; with
// `commands`, the compensated real-time command and compute_commands too (they add a stroke
// check of the compensated command, which a stroke-bound test would trip on its own).
std::vector<Status> decisions(const Model& model, const Pose& p, bool commands) {
  LegState st;
  EXPECT_EQ(inverse_kinematics(model, p, st), Status::Ok);
  LimitReport r;
  std::vector<Status> out{check_limits(model, st, r)};
  Vector6d cmd;
  out.push_back(motor_commands(model, p, Strategy::Conventional, cmd, r));
  if (commands) {
    out.push_back(motor_commands(model, p, Strategy::Compensated, cmd, r));
    CommandReport rep;
    out.push_back(compute_commands(model, p, rep));
  }
  return out;
}

// The limit that `set` writes is put on the pose's own value of it (`value`), then 1 ulp past
// it (the value outside the bound by 1 ulp: inside the tolerance) and 1e-12 relative past it.
// `upper`: the value must stay at or below the bound. Every path accepts the first two and
// refuses the third with `refused`.
template <class Set>
void expect_on_the_bound_is_inside(const Pose& p, double value, bool upper, Set set, Status refused, bool commands) {
  const double toward = upper ? -INFINITY : INFINITY;
  const double past = upper ? value * (1.0 - 1e-12) : value * (1.0 + 1e-12);
  for (const double bound : {value, std::nextafter(value, toward), past}) {
    ModelSpec spec = seed_model().spec();
    set(spec, bound);
    const Model model(spec);
    const Status expected = bound == past ? refused : Status::Ok;
    SCOPED_TRACE(::testing::Message() << std::setprecision(17) << str(p) << " value " << value << " bound " << bound);
    for (const Status s : decisions(model, p, commands)) EXPECT_EQ(s, expected) << to_string(s);
  }
}

Pose pose_of(double x, double y, double z, double roll_deg, double pitch_deg, double yaw_deg) {
  return Pose::from_vector((Vector6d() << x, y, z, deg2rad(roll_deg), deg2rad(pitch_deg), deg2rad(yaw_deg)).finished());
}

TEST(Limits, AStrokeEndIsInsideOnEveryPathAndPastItOutside) {
  const Pose up = pose_of(0.05, -0.02, 0.25, 2, -3, 5);
  LegState st;
  ASSERT_EQ(inverse_kinematics(seed_model(), up, st), Status::Ok);
  expect_on_the_bound_is_inside(
      up, st.length.maxCoeff(), true, [](ModelSpec& s, double b) { s.limits.length_max = b; }, Status::StrokeAboveMax,
      false);
  const Pose down = pose_of(-0.04, 0.03, -0.2, -2, 1, -6);
  ASSERT_EQ(inverse_kinematics(seed_model(), down, st), Status::Ok);
  expect_on_the_bound_is_inside(
      down, st.length.minCoeff(), false, [](ModelSpec& s, double b) { s.limits.length_min = b; },
      Status::StrokeBelowMin, false);
}

TEST(Limits, ABendOnItsLimitIsInsideOnEveryPathAndPastItOutside) {
  for (const Pose& p : {pose_of(0.1, 0, 0, 0, -20, 0), pose_of(0.05, 0.05, 0, 8, 5, 10)}) {
    LegState st;
    ASSERT_EQ(inverse_kinematics(seed_model(), p, st), Status::Ok);
    Vector6d bb, bp;
    bend_angles(seed_model(), st, bb, bp);
    const Status refused = bb.maxCoeff() >= bp.maxCoeff() ? Status::BendBase : Status::BendPlatform;
    expect_on_the_bound_is_inside(
        p, std::max(bb.maxCoeff(), bp.maxCoeff()), true, [](ModelSpec& s, double b) { s.limits.bend_max = b; }, refused,
        true);
  }
}

TEST(Limits, ASingularityMarginMetExactlyIsInsideOnEveryPathAndPastItOutside) {
  // The margin must stay below the angle at home (the model checks home): a pose that closes it.
  const auto smallest = [](const Model& model, const LegState& st, Status& which) {
    double angle = kPi;
    for (int i = 0; i < kLegs; ++i) {
      const Vector3d s = st.s_B.row(i).transpose();
      const Vector3d axes[2] = {model.leg(i).axis_base_B, st.axis_platform_B.row(i).transpose()};
      for (int j = 0; j < 2; ++j) {
        const double a = std::atan2(s.cross(axes[j]).norm(), std::abs(s.dot(axes[j])));
        if (a < angle) {
          angle = a;
          which = j == 0 ? Status::SingularBase : Status::SingularPlatform;
        }
      }
    }
    return angle;
  };
  LegState home;
  ASSERT_EQ(inverse_kinematics(seed_model(), Pose{}, home), Status::Ok);
  Status which = Status::Ok;
  const double at_home = smallest(seed_model(), home, which);
  int tested = 0;
  for (const Pose& p : {pose_of(0.1, 0, 0, 0, 0, 15), pose_of(0, 0.1, 0, 0, 0, -15), pose_of(0.05, 0.05, 0.1, 5, 5, 20),
                        pose_of(0, 0, 0, 0, 0, 30)}) {
    LegState st;
    ASSERT_EQ(inverse_kinematics(seed_model(), p, st), Status::Ok);
    const double angle = smallest(seed_model(), st, which);
    if (!(angle < at_home - 1e-6)) continue;
    expect_on_the_bound_is_inside(
        p, angle, false, [](ModelSpec& s, double b) { s.limits.singularity_margin = b; }, which, true);
    ++tested;
  }
  EXPECT_GT(tested, 0);
}

TEST(Limits, AConditionNumberOnItsLimitIsInsideOnEveryPathAndPastItOutside) {
  const Pose p = pose_of(0, 0, 0.1, 0, 0, 30);  // kappa 9.06, above home's 8.87
  LegState st;
  ASSERT_EQ(inverse_kinematics(seed_model(), p, st), Status::Ok);
  double condition;
  ASSERT_EQ(jacobian_condition(seed_model(), st, condition), Status::Ok);
  expect_on_the_bound_is_inside(
      p, condition, true, [](ModelSpec& s, double b) { s.limits.jacobian_condition_max = b; },
      Status::PlatformSingularity, true);
}

TEST(Limits, CommandsOnTheStrokeEndsAndWithinTheToleranceAreInsideBeyondOutside) {
  const Model& m = seed_model();
  const double lo = m.spec().limits.length_min, hi = m.spec().limits.length_max;
  EXPECT_EQ(m.length_max_accepted(), accepted_max(hi));
  EXPECT_EQ(m.length_min_accepted(), accepted_min(lo));
  EXPECT_GT(accepted_max(hi), std::nextafter(std::nextafter(hi, INFINITY), INFINITY));  // a few ulp, not one
  EXPECT_LT(accepted_max(hi), hi * (1.0 + 1e-15));
  LimitReport r;
  for (int leg = 0; leg < kLegs; ++leg) {
    SCOPED_TRACE(leg);
    Vector6d cmd = m.length_home();
    for (const double inside :
         {hi, std::nextafter(hi, INFINITY), accepted_max(hi), lo, std::nextafter(lo, 0.0), accepted_min(lo)}) {
      cmd[leg] = inside;
      EXPECT_EQ(check_stroke(m, cmd, r), Status::Ok) << std::setprecision(17) << inside;
    }
    cmd[leg] = std::nextafter(accepted_max(hi), INFINITY);
    EXPECT_EQ(check_stroke(m, cmd, r), Status::StrokeAboveMax);
    EXPECT_EQ(r.leg, leg);
    EXPECT_EQ(r.bound, hi);  // the configured bound, not the widened one
    cmd[leg] = std::nextafter(accepted_min(lo), 0.0);
    EXPECT_EQ(check_stroke(m, cmd, r), Status::StrokeBelowMin);
    EXPECT_EQ(r.leg, leg);
  }
}

// ---- platform (Jacobian) singularity --------------------------------------------------------

// The condition number by Eigen: the Jacobian of twist_jacobian / length_jacobian, scaled, its
// exact inverse, and the 1-norm as the largest column sum.
double condition_by_eigen(const Model& model, const LegState& st) {
  Matrix6d J, J_twist;
  length_jacobian(st, J);
  if (model.has_twist()) {
    EXPECT_EQ(twist_jacobian(model, st, J_twist), Status::Ok);
    J -= model.geometry().twist_gain.asDiagonal() * J_twist;
  }
  J.rightCols<3>() /= model.condition_length();
  const auto norm1 = [](const Matrix6d& A) { return A.cwiseAbs().colwise().sum().maxCoeff(); };
  return norm1(J) * norm1(J.fullPivLu().inverse());
}

TEST(Limits, JacobianConditionMatchesAnIndependentComputation) {
  std::mt19937_64 rng(kSeed + 30);
  double worst = 0.0;
  for (int m = 0; m < 10; ++m) {
    const Model model = m == 0 ? seed_model() : random_platform(rng);
    for (int n = 0; n < 100; ++n) {
      LegState st;
      ASSERT_EQ(inverse_kinematics(model, random_pose(rng, 0.3, deg2rad(20)), st), Status::Ok);
      double c;
      if (jacobian_condition(model, st, c) == Status::SingularBase || std::isnan(c)) continue;
      const double expected = condition_by_eigen(model, st);
      worst = std::max(worst, std::abs(c - expected) / expected);
    }
  }
  report("relative difference", worst);
  EXPECT_LT(worst, 1e-10);
}

TEST(Limits, JacobianConditionIsBetweenTheTwoNormBoundsOfTheSvd) {
  // ||A||_1 ||A^-1||_1 lies within a factor 6 of the 2-norm condition number (n = 6).
  LegState st;
  ASSERT_EQ(inverse_kinematics(seed_model(), Pose{}, st), Status::Ok);
  double c;
  ASSERT_EQ(jacobian_condition(seed_model(), st, c), Status::Ok);
  Matrix6d J, J_twist;
  length_jacobian(st, J);
  ASSERT_EQ(twist_jacobian(seed_model(), st, J_twist), Status::Ok);
  J -= seed_model().geometry().twist_gain.asDiagonal() * J_twist;
  J.rightCols<3>() /= seed_model().condition_length();
  const Eigen::JacobiSVD<Matrix6d> svd(J);
  const double c2 = svd.singularValues()(0) / svd.singularValues()(5);
  EXPECT_GE(c, c2 / 6);
  EXPECT_LE(c, c2 * 6);
}

TEST(Limits, SeedWorkspaceIsFarInsideTheConditionLimit) {
  // The paper's tests (about 9-10.5) and random poses inside the other limits (at most about 11)
  // pass the default bound of 50 with a factor 4 to spare.
  std::mt19937_64 rng(kSeed + 31);
  ModelSpec spec = seed_model().spec();
  spec.limits.jacobian_condition_max = 1e300;
  const Model unbounded(spec);
  double worst = 0.0;
  for (int n = 0; n < 20000; ++n) {
    const Pose p = random_valid_pose(unbounded, rng, 0.8, deg2rad(40));
    LegState st;
    ASSERT_EQ(inverse_kinematics(unbounded, p, st), Status::Ok);
    double c;
    ASSERT_EQ(jacobian_condition(unbounded, st, c), Status::Ok);
    worst = std::max(worst, c);
  }
  report("largest condition number", worst);
  EXPECT_LT(worst, seed_model().spec().limits.jacobian_condition_max / 4);
}

TEST(Limits, PureYawTowardsTheSingularityIsRefusedByTheConditionLimit) {
  // With stroke and bend limits wide enough, pure yaw reaches the seed's singularity at 90 deg.
  ModelSpec spec = seed_model().spec();
  spec.limits.length_min = 0.5;
  spec.limits.length_max = 4.0;
  spec.limits.bend_max = deg2rad(89);
  const Model model(spec);
  double previous = 0.0, refused_at = 0.0;
  for (int k = 0; k <= 900; ++k) {
    Pose p;
    p.rpy[2] = deg2rad(0.1 * k);
    LegState st;
    ASSERT_EQ(inverse_kinematics(model, p, st), Status::Ok);
    double c;
    const Status s = jacobian_condition(model, st, c);
    if (k > 300) {  // from 30 deg on it rises towards 90 deg
      EXPECT_GT(c, previous) << "yaw " << 0.1 * k;
    }
    previous = c;
    if (k % 50 == 0) std::printf("  yaw %4.1f deg: condition %.4g\n", 0.1 * k, c);
    LimitReport r;
    EXPECT_EQ(check_limits(model, st, r), s);
    if (s == Status::Ok) continue;
    EXPECT_EQ(s, Status::PlatformSingularity);
    EXPECT_EQ(r.leg, -1);
    EXPECT_EQ(r.value, c);
    EXPECT_EQ(r.bound, spec.limits.jacobian_condition_max);
    if (refused_at == 0.0) refused_at = 0.1 * k;
    // Neither the command functions nor compute_commands emit a command there.
    Vector6d cmd = Vector6d::Constant(-1.0);
    LimitReport lim;
    EXPECT_EQ(motor_commands(model, p, Strategy::Compensated, cmd, lim), Status::PlatformSingularity);
    EXPECT_EQ(motor_commands(model, p, Strategy::Conventional, cmd, lim), Status::PlatformSingularity);
    EXPECT_EQ(cmd, Vector6d::Constant(-1.0));
    CommandReport rep;
    EXPECT_EQ(compute_commands(model, p, rep), Status::PlatformSingularity);
  }
  std::printf("  refused from yaw %.1f deg\n", refused_at);
  EXPECT_GT(refused_at, 80.0);
  EXPECT_LT(refused_at, 88.0);  // measured: 86.3 deg
  EXPECT_GT(previous, 1e3);     // at 90 deg
}

TEST(Limits, ModelRefusesAHomeBeyondTheConditionLimit) {
  ModelSpec spec = seed_model().spec();
  spec.limits.jacobian_condition_max = 5.0;  // the seed's home is at 8.9
  expect_error_line([&] { (void)Model(spec); }, "limits.jacobian_condition_max:", {"home", "8.8"});
  spec.limits.jacobian_condition_max = 1.0;
  expect_error_line([&] { (void)Model(spec); }, "limits.jacobian_condition_max:", {"> 1"});
  spec.limits.jacobian_condition_max = std::nan("");
  expect_error_line([&] { (void)Model(spec); }, "limits.jacobian_condition_max:", {"finite"});
}

}  // namespace
}  // namespace hexatwist::test

namespace hexatwist::test {
namespace {

// nearest_limit's margin says the same as check_limits: positive inside every limit, not positive
// outside one (poses on both sides, across the seed's workspace and past it).
TEST(Limits, NearestLimitMarginIsPositiveExactlyWhenThePoseIsInsideEveryLimit) {
  const Model& model = seed_model();
  std::mt19937_64 rng(kSeed + 70);
  int inside = 0, outside = 0;
  for (int n = 0; n < 20000; ++n) {
    const Pose p = n % 2 ? random_pose(rng, 0.3, deg2rad(20)) : random_pose(rng, 0.7, deg2rad(45));
    LegState st;
    ASSERT_EQ(inverse_kinematics(model, p, st), Status::Ok);
    double condition;
    (void)jacobian_condition(model, st, condition);
    LimitReport nearest, check;
    double margin;
    nearest_limit(model, st, condition, nearest, margin);
    if (std::abs(margin) < 1e-9) continue;  // on a limit to rounding: either answer is right
    const bool ok = check_limits(model, st, check) == Status::Ok;
    ASSERT_EQ(margin > 0, ok) << str(p) << " margin " << margin << " nearest " << to_string(nearest.status);
    ASSERT_TRUE(is_limit(nearest.status)) << str(p);
    ASSERT_LE(margin, 1.0);
    (ok ? inside : outside) += 1;
  }
  EXPECT_GT(inside, 1000);
  EXPECT_GT(outside, 1000);
}

TEST(Limits, NearestLimitOnTheEdgeOfTheReachIsTheLimitMetThereWithMarginZero) {
  const Model& model = seed_model();
  for (int k = 0; k < 6; ++k) {
    AxisRange range;
    ASSERT_EQ(axis_range(model, k, Strategy::Compensated, range), Status::Ok);
    Vector6d q = Vector6d::Zero();
    q[k] = range.upper;
    LegState st;
    ASSERT_EQ(inverse_kinematics(model, Pose::from_vector(q), st), Status::Ok);
    double condition, margin;
    LimitReport nearest;
    (void)jacobian_condition(model, st, condition);
    nearest_limit(model, st, condition, nearest, margin);
    // The reach ends on a limit of the motor-side command or of the pose; the stroke of the
    // command differs from the pose's by the twist term, so allow its size in the margin.
    EXPECT_NEAR(margin, 0.0, 0.01) << "coordinate " << k;
    if (range.upper_limit.status != Status::StrokeAboveMax && range.upper_limit.status != Status::StrokeBelowMin) {
      EXPECT_EQ(nearest.status, range.upper_limit.status) << k;
      EXPECT_EQ(nearest.leg, range.upper_limit.leg) << k;
    }
  }
  // Home is far from every limit.
  LegState home;
  ASSERT_EQ(inverse_kinematics(model, Placement{}, home), Status::Ok);
  double condition, margin;
  LimitReport nearest;
  ASSERT_EQ(jacobian_condition(model, home, condition), Status::Ok);
  nearest_limit(model, home, condition, nearest, margin);
  EXPECT_GT(margin, 0.3);
}

}  // namespace
}  // namespace hexatwist::test
