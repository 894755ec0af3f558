// SPDX-License-Identifier: BSD-3-Clause
// Reach along each pose coordinate alone (workspace.hpp): every value inside the interval is
// accepted, the values just past its ends are refused by the limit it names, and the search
// agrees with itself at another step size.
#include "hexatwist/kinematics/workspace.hpp"

#include "support.hpp"

namespace hexatwist::test {
namespace {

// motor_commands for coordinate k at value v, the others at home.
Status command_at(const Model& model, int k, double v, LimitReport& report) {
  Vector6d q = Vector6d::Zero();
  q[k] = v;
  Vector6d command;
  return motor_commands(model, Pose::from_vector(q), Strategy::Compensated, command, report);
}

TEST(Workspace, EveryValueInsideTheReachIsAcceptedAndJustPastItIsRefusedByTheNamedLimit) {
  const Model& model = seed_model();
  for (int k = 0; k < 6; ++k) {
    AxisRange range;
    ASSERT_EQ(axis_range(model, k, Strategy::Compensated, range), Status::Ok) << k;
    EXPECT_LT(range.lower, 0.0);
    EXPECT_GT(range.upper, 0.0);
    LimitReport report;
    // Inside: the whole interval, on a grid finer than the march step.
    for (int n = 0; n <= 400; ++n) {
      const double v = range.lower + (range.upper - range.lower) * n / 400.0;
      ASSERT_EQ(command_at(model, k, v, report), Status::Ok) << "coordinate " << k << " value " << v;
    }
    // Just past each end (a few bisection tolerances): refused, by the limit the range names.
    for (const auto& [end, limit, sign] :
         {std::tuple{range.upper, range.upper_limit, 1.0}, std::tuple{range.lower, range.lower_limit, -1.0}}) {
      ASSERT_TRUE(is_limit(limit.status)) << "coordinate " << k;
      EXPECT_EQ(command_at(model, k, end + sign * 1e-8, report), limit.status) << "coordinate " << k;
      EXPECT_EQ(report.leg, limit.leg);
    }
  }
}

TEST(Workspace, AFinerMarchFindsTheSameEnds) {
  // The reach is one interval here: the march step does not change where it ends.
  const Model& model = seed_model();
  AxisRangeOptions fine;
  fine.linear_step = 1e-4;
  fine.angular_step = 1e-4;
  for (int k = 0; k < 6; ++k) {
    AxisRange a, b;
    ASSERT_EQ(axis_range(model, k, Strategy::Compensated, a), Status::Ok);
    ASSERT_EQ(axis_range(model, k, Strategy::Compensated, b, fine), Status::Ok);
    EXPECT_NEAR(a.upper, b.upper, 1e-8) << k;
    EXPECT_NEAR(a.lower, b.lower, 1e-8) << k;
  }
}

TEST(Workspace, TheSearchBoundEndsAReachWithoutALimitAndBadArgumentsAreRefused) {
  AxisRange range;
  AxisRangeOptions small;
  small.linear_bound = 0.05;  // well inside the stroke
  ASSERT_EQ(axis_range(seed_model(), 0, Strategy::Compensated, range, small), Status::Ok);
  EXPECT_DOUBLE_EQ(range.upper, 0.05);
  EXPECT_DOUBLE_EQ(range.lower, -0.05);
  EXPECT_EQ(range.upper_limit.status, Status::Ok);
  EXPECT_EQ(axis_range(seed_model(), 6, Strategy::Compensated, range), Status::NonFiniteInput);
  EXPECT_EQ(axis_range(seed_model(), -1, Strategy::Compensated, range), Status::NonFiniteInput);
  AxisRangeOptions bad;
  bad.angular_step = 0.0;
  EXPECT_EQ(axis_range(seed_model(), 5, Strategy::Compensated, range, bad), Status::NonFiniteInput);
}

}  // namespace
}  // namespace hexatwist::test
