// SPDX-License-Identifier: BSD-3-Clause
// What the design subsystem's tests share: a required workspace of the seed platform.
#pragma once

#include <vector>

#include "hexatwist/design/required_workspace.hpp"
#include "support.hpp"

namespace hexatwist::test {

/// The seed's required workspace: the study's four tests at 11 samples each and `random` combined poses.
inline std::vector<Pose> required_poses(int random) {
  RequiredWorkspaceSpec spec;
  spec.test_samples = 11;
  spec.random = random;
  RequiredWorkspace w;
  EXPECT_EQ(required_workspace(seed_model(), StudySpec{}, spec, Strategy::Compensated, w), Status::Ok);
  return w.poses;
}

}  // namespace hexatwist::test
