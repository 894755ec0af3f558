// SPDX-License-Identifier: BSD-3-Clause
// The required workspace (required_workspace.hpp, docs/theory/design.md §17): the tests' poses,
// the random combined poses and which of them the platform reaches.
#include "hexatwist/design/required_workspace.hpp"

#include <gtest/gtest.h>

#include "support.hpp"

namespace hexatwist {
namespace {

TEST(RequiredWorkspace, HoldsTheFourTestsAndTheReachedShareOfTheRandomPoses) {
  const Model& model = test::seed_model();
  RequiredWorkspaceSpec spec;
  spec.random = 4000;
  RequiredWorkspace w;
  ASSERT_EQ(required_workspace(model, StudySpec{}, spec, Strategy::Compensated, w), Status::Ok);
  EXPECT_EQ(w.test_poses, 4u * 41u);  // the seed reaches its four tests
  EXPECT_EQ(w.tests_dropped, 0u);
  EXPECT_EQ(w.random_drawn, 4000u);
  const double refused = 1.0 - static_cast<double>(w.random_reached) / 4000.0;
  test::report("share of the random combined poses the seed does not reach", refused);
  EXPECT_NEAR(refused, 0.09, 0.03);  // the "about 9 %"
  ASSERT_EQ(w.poses.size(), w.test_poses + w.random_reached);
  // The tests' ends are their amplitudes: Lz first, +-0.5 m in z.
  EXPECT_EQ(w.poses.front().position.z(), -0.5);
  EXPECT_EQ(w.poses[40].position.z(), 0.5);
  Vector6d command;
  LimitReport r;
  for (const Pose& p : w.poses) EXPECT_EQ(motor_commands(model, p, Strategy::Compensated, command, r), Status::Ok);
}

TEST(RequiredWorkspace, RandomPosesAreUniformInTheirBoxAndTheSameForAnyCount) {
  RequiredWorkspaceSpec spec;
  const std::vector<Pose> a = random_combined_poses(spec, 0, 20000);
  const std::vector<Pose> b = random_combined_poses(spec, 100, 50);
  for (std::size_t k = 0; k < b.size(); ++k) EXPECT_EQ(a[100 + k].to_vector(), b[k].to_vector());
  Vector6d mean = Vector6d::Zero(), lo = Vector6d::Constant(1e9), hi = -lo;
  for (const Pose& p : a) {
    const Vector6d q = p.to_vector();
    mean += q / a.size();
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  for (int c = 0; c < 6; ++c) {
    const double range = c < 3 ? spec.linear : spec.angular;
    EXPECT_NEAR(mean[c], 0.0, 4 * range / std::sqrt(3.0 * a.size()));
    EXPECT_GE(lo[c], -range);
    EXPECT_LE(hi[c], range);
    EXPECT_LT(lo[c], -0.99 * range);
    EXPECT_GT(hi[c], 0.99 * range);
  }
  spec.seed = 2;
  EXPECT_NE(random_combined_poses(spec, 0, 1)[0].to_vector(), a[0].to_vector());
}

TEST(RequiredWorkspace, RefusesABadSpecNamingTheField) {
  // Each field just past its range (check_required_workspace_spec), and the empty workspace.
  const auto refused = [](RequiredWorkspaceSpec spec, std::string_view field) {
    RequiredWorkspace w;
    try {
      (void)required_workspace(test::seed_model(), StudySpec{}, spec, Strategy::Compensated, w);
      ADD_FAILURE() << field << ": not refused";
    } catch (const ParameterError& e) {
      EXPECT_EQ(e.parameter(), field) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("required workspace: ", 0), 0U) << e.what();
    }
  };
  RequiredWorkspaceSpec s;
  s.test_samples = 1;
  refused(s, "test_samples");
  s = {};
  s.test_samples = kMaxTestSamples + 1;
  refused(s, "test_samples");
  s = {};
  s.random = -1;
  refused(s, "random");
  s = {};
  s.linear = std::nan("");
  refused(s, "linear");
  s.linear = kMaxRequiredLinear * (1 + 1e-12);
  refused(s, "linear");
  s = {};
  s.angular = -1e-9;
  refused(s, "angular");
  s = {};
  s.tests = false;
  s.random = 0;
  refused(s, "random");
  // On the ends: accepted.
  s = {};
  s.test_samples = 2;
  s.random = 0;
  s.linear = kMaxRequiredLinear;
  s.angular = kMaxRequiredAngular;
  EXPECT_NO_THROW(check_required_workspace_spec(s));
}

}  // namespace
}  // namespace hexatwist
