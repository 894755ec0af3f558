// SPDX-License-Identifier: BSD-3-Clause
// The study's claims on the seed platform's default tests: exact compensation, the compensated
// loop adds nothing to the servo's own error, and the twist error grows away from home.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "hexatwist/error.hpp"
#include "hexatwist/io/config.hpp"
#include "hexatwist/simulation/study.hpp"

namespace hexatwist {
namespace {

TEST(Study, TheSeedTestsInTableOneOrder) {
  const auto tests = seed_tests(StudySpec{});
  ASSERT_EQ(tests.size(), 4u);
  EXPECT_EQ(tests[0].name, "Lz");
  EXPECT_EQ(tests[1].name, "Lx");
  EXPECT_EQ(tests[2].name, "Rz");
  EXPECT_EQ(tests[3].name, "Ry");
  EXPECT_EQ(tests[2].coordinate, 5);
  EXPECT_DOUBLE_EQ(tests[3].amplitude, deg2rad(30));
}

TEST(Study, ErrorStats) {
  const ErrorStats s = error_stats({3.0, 4.0, 0.0, 0.0});
  EXPECT_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.rms, 2.5);
}

TEST(Study, KeepAfterDropsTheTicksBeforeAndRecomputesTheStatistics) {
  TestRun run;
  for (StrategyRun* r : {&run.conventional, &run.compensated}) {
    r->samples.resize(4);
    for (int k = 0; k < 4; ++k) {
      r->samples[static_cast<std::size_t>(k)].time = 0.5 * k;
      r->samples[static_cast<std::size_t>(k)].error = r == &run.conventional ? 4.0 - k : 1.0 + k;
      r->samples[static_cast<std::size_t>(k)].error_twist_only = 0.1 * k;
    }
  }
  run.tracking_only = {9.0, 3.0, 0.0, 4.0};
  keep_after(run, 0.5);  // ticks at 1.0 and 1.5 s stay
  ASSERT_EQ(run.conventional.samples.size(), 2u);
  ASSERT_EQ(run.compensated.samples.size(), 2u);
  EXPECT_EQ(run.conventional.samples[0].time, 1.0);
  EXPECT_EQ(run.tracking_only, (std::vector<double>{0.0, 4.0}));
  EXPECT_EQ(run.conventional.total.max, 2.0);
  EXPECT_EQ(run.compensated.total.max, 4.0);
  EXPECT_DOUBLE_EQ(run.compensated.twist_only.rms, std::sqrt((0.04 + 0.09) / 2));
  EXPECT_EQ(run.compensated.tracking_only.max, 4.0);
  EXPECT_DOUBLE_EQ(run.conventional.tracking_only.rms, std::sqrt(8.0));
}

TEST(Study, StudyTestFindsEachSeedTestByNameAndRefusesOthersInOneLine) {
  for (const StudyTest& t : seed_tests(StudySpec{}))
    EXPECT_EQ(study_test(StudySpec{}, t.name).coordinate, t.coordinate);
  try {
    (void)study_test(StudySpec{}, "Lq\n");
    ADD_FAILURE() << "Lq found";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "unknown test 'Lq\\x0a'; expected Lz, Lx, Rz or Ry");
  }
}

TEST(Study, RunMetricsAreTheLargestOfTheTicksAndCountTheSaturatedOnes) {
  // Three hand-made ticks: torques, motor-side targets and real poses whose metrics are known.
  const Rig& rig = default_config().rig;
  const double limit = rig.servo().torque_limit;
  std::vector<SimulationSample> ticks(3);
  ticks[0].torque << 1, -2, 0, 0, 0, 0;
  ticks[1].torque << 0, 0, -limit, 3, 0, 0;  // at the limit: saturated
  ticks[2].torque << 0, 0, 0, 0, 0, 0.5 * limit;
  ticks[1].command << 0, 0, 0, 0, 0, 2e-3;
  ticks[2].motor << -3e-3, 0, 0, 0, 0, 0;
  ticks[2].actual << 0, 0, 0, 0, 0, 0.25;  // yaw 0.25 rad off the commanded 0.1
  ticks[2].desired << 0, 0, 0, 0, 0, 0.1;
  const RunMetrics m = run_metrics(rig, ticks);
  EXPECT_EQ(m.max_torque, limit);
  EXPECT_EQ(m.saturated_ticks, 1u);
  EXPECT_EQ(m.max_following_error, 3e-3);
  EXPECT_NEAR(m.max_orientation_error, 0.15, 1e-12);
}

TEST(Study, CheckStudyRefusesAMotionTooLongToSampleNamingItsBlock) {
  StudySpec spec;
  EXPECT_NO_THROW(check_study(spec, 1e-3));
  spec.linear.jerk = 1e-12;  // within its range, but a move of days
  try {
    check_study(spec, 1e-3);
    ADD_FAILURE() << "a jerk of 1e-12 m/s^3 passed";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("study.linear: a test takes ", 0), 0u) << e.what();
  }
  spec = StudySpec{};
  spec.angular_amplitude = deg2rad(1e3);
  EXPECT_THROW(check_study(spec, 1e-3), Error);
}

// One default test per parameter (the full seed test: about 0.8 s each).
class SeedTest : public ::testing::TestWithParam<int> {};

TEST_P(SeedTest, CompensationIsExactAndAddsNothingToTheServoError) {
  const Config config = default_config();
  const StudyTest test = seed_tests(config.study)[static_cast<std::size_t>(GetParam())];
  const Trajectory trajectory = test_trajectory(config.study, test, config.rig.control_period());
  TestRun run;
  SimulationIssue issue;
  ASSERT_EQ(run_test(config.rig, trajectory, run, issue), Status::Ok) << test.name;
  // Exact compensation: with perfect servos the compensated command puts the point where it belongs.
  EXPECT_LE(run.compensated.twist_only.max, 2e-11) << test.name;  // issue: 1 nm; measured <= 1.8e-12 m
  // The compensated loop is the servo's own error: within 1 um of the twist-free run, tick by tick.
  double worst = 0.0;
  for (std::size_t k = 0; k < run.tracking_only.size(); ++k)
    worst = std::max(worst, run.compensated.samples[k].error - run.tracking_only[k]);
  EXPECT_LE(worst, 1e-6) << test.name;  // the issue's 1 um; measured <= 1.0e-7 m (Lx)
  EXPECT_LE(run.compensated.total.max - run.compensated.tracking_only.max, 1e-6) << test.name;
  // The conventional loop carries the twist error, far above the servo's.
  // Measured 7-32x on the full mechanism (20-90x without the screw's efficiency, whose load-dependent
  // losses the integrators take out: theory §9).
  EXPECT_GT(run.conventional.total.max, 5 * run.conventional.tracking_only.max) << test.name;
  EXPECT_NEAR(run.conventional.total.max, run.conventional.twist_only.max, 0.02 * run.conventional.twist_only.max);
  EXPECT_EQ(run.conventional.tracking_only.max, run.compensated.tracking_only.max);
}

// The paper states the growth for the linear tests: Lz and Lx.
class LinearSeedTest : public ::testing::TestWithParam<int> {};

TEST_P(LinearSeedTest, ConventionalTwistErrorGrowsAwayFromHome) {
  const Config config = default_config();
  const StudyTest test = seed_tests(config.study)[static_cast<std::size_t>(GetParam())];
  ASSERT_LT(test.coordinate, 3);
  const Trajectory trajectory = test_trajectory(config.study, test, config.rig.control_period());
  TestRun run;
  SimulationIssue issue;
  ASSERT_EQ(run_test(config.rig, trajectory, run, issue), Status::Ok);
  // On the way out (home -> +amplitude) and on the way back past home to -amplitude, the
  // quasi-static twist error rises with the distance from home.
  const auto& s = run.conventional.samples;
  double last_d = 0.0, last_e = 0.0;
  int rising = 0;
  bool out = true;
  for (const SimulationSample& x : s) {
    const double d = std::abs(x.desired[test.coordinate]);
    if (out && d + 1e-12 < last_d) out = false;  // the first move has ended
    if (out && d > last_d + 1e-6) {
      EXPECT_GE(x.error_twist_only, last_e - 1e-12) << "at " << d;
      rising += x.error_twist_only > last_e ? 1 : 0;
      last_e = x.error_twist_only;
      last_d = d;
    }
  }
  EXPECT_GT(rising, 100);
  EXPECT_GT(run.conventional.twist_only.max, 1e-4);  // 0.1 mm and more at 0.5 m
}

INSTANTIATE_TEST_SUITE_P(Lz_Lx_Rz_Ry, SeedTest, ::testing::Values(0, 1, 2, 3));
INSTANTIATE_TEST_SUITE_P(Lz_Lx, LinearSeedTest, ::testing::Values(0, 1));

}  // namespace
}  // namespace hexatwist
