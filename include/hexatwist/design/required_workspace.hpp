// SPDX-License-Identifier: BSD-3-Clause
// The poses a platform must reach, for its design and its tolerance analysis (docs/theory/design.md
// §17): the study's four tests at their amplitudes and random combined poses within a box of
// translations and rotations, kept where the platform reaches them.
#pragma once

#include <cstdint>
#include <vector>

#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/simulation/study.hpp"

namespace hexatwist {

/// What the required workspace holds.
struct RequiredWorkspaceSpec {
  bool tests = true;               ///< the study's four tests (Lz, Lx, Rz, Ry) at their amplitudes
  int test_samples = 41;           ///< poses per test, evenly from -amplitude to +amplitude (>= 2)
  int random = 2000;               ///< combined poses drawn, every coordinate at once ...
  double linear = 0.25;            ///< ... uniform in +-linear for x, y, z [m]
  double angular = deg2rad(15.0);  ///< ... and +-angular for roll, pitch, yaw [rad]
  std::uint64_t seed = 1;          ///< of the draw (pose k is the same for any count above k)
};

/// The required workspace of a platform.
struct RequiredWorkspace {
  std::vector<Pose> poses;         ///< the poses kept: the tests' first, then the random ones
  std::size_t test_poses = 0;      ///< of which from the tests
  std::size_t tests_dropped = 0;   ///< test poses the platform does not reach (left out)
  std::size_t random_drawn = 0;    ///< random poses drawn
  std::size_t random_reached = 0;  ///< of which reached (kept)
};

/// The largest settings a required workspace takes: poses per test, random poses, the ranges [m, rad].
inline constexpr int kMaxTestSamples = 1000000, kMaxRandomPoses = 1000000000;
inline constexpr double kMaxRequiredLinear = 10.0, kMaxRequiredAngular = 3.141592653589793;

/// The one check of a RequiredWorkspaceSpec (required_workspace runs it; the CLI's --workspace
/// and Python's keywords reach it): throws hexatwist::ParameterError naming the field out of its
/// range (test_samples 2 to kMaxTestSamples, random 0 to kMaxRandomPoses, linear 0 to
/// kMaxRequiredLinear, angular 0 to kMaxRequiredAngular) or "random" when there are no tests and
/// no random poses (an empty workspace).
void check_required_workspace_spec(const RequiredWorkspaceSpec& spec);

/// The required workspace `spec` of `model`, a pose kept when motor_commands accepts it for
/// `strategy`; the tests come from `study` (seed_tests). Throws as check_required_workspace_spec.
[[nodiscard]] Status required_workspace(const Model& model, const StudySpec& study, const RequiredWorkspaceSpec& spec,
                                        Strategy strategy, RequiredWorkspace& out);

/// The `count` random poses of `spec` starting at draw `first` [m, rad] (the draw of
/// required_workspace, before it keeps the reached ones).
std::vector<Pose> random_combined_poses(const RequiredWorkspaceSpec& spec, std::size_t first, std::size_t count);

}  // namespace hexatwist
