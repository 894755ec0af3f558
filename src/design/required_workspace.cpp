// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/design/required_workspace.hpp"

#include <fmt/format.h>

#include <cmath>

#include "design/sampling.hpp"
#include "hexatwist/error.hpp"

namespace hexatwist {

std::vector<Pose> random_combined_poses(const RequiredWorkspaceSpec& spec, std::size_t first, std::size_t count) {
  std::vector<Pose> poses(count);
  for (std::size_t k = 0; k < count; ++k) {
    detail::SampleStream r(spec.seed, first + k);
    Pose& p = poses[k];
    for (int c = 0; c < 3; ++c) p.position[c] = spec.linear * r.symmetric();
    for (int c = 0; c < 3; ++c) p.rpy[c] = spec.angular * r.symmetric();
  }
  return poses;
}

void check_required_workspace_spec(const RequiredWorkspaceSpec& s) {
  const auto refuse = [](std::string message, const char* field) {
    throw ParameterError("required workspace: " + std::move(message), field);
  };
  if (s.test_samples < 2 || s.test_samples > kMaxTestSamples)
    refuse(fmt::format("expected 2 to {} poses per test, got {}", kMaxTestSamples, s.test_samples), "test_samples");
  if (s.random < 0 || s.random > kMaxRandomPoses)
    refuse(fmt::format("expected 0 to {} random poses, got {}", kMaxRandomPoses, s.random), "random");
  if (!(s.linear >= 0.0 && s.linear <= kMaxRequiredLinear))
    refuse(fmt::format("expected a linear range of 0 to {:g} m, got {:g}", kMaxRequiredLinear, s.linear), "linear");
  if (!(s.angular >= 0.0 && s.angular <= kMaxRequiredAngular))
    refuse(fmt::format("expected an angular range of 0 to 180 deg, got {:g} deg", rad2deg(s.angular)), "angular");
  if (!s.tests && s.random == 0) refuse("no tests and no random poses: the workspace would be empty", "random");
}

Status required_workspace(const Model& model, const StudySpec& study, const RequiredWorkspaceSpec& spec,
                          Strategy strategy, RequiredWorkspace& out) {
  check_required_workspace_spec(spec);
  out = RequiredWorkspace{};
  Vector6d command;
  LimitReport report;
  if (spec.tests) {
    for (const StudyTest& test : seed_tests(study)) {
      for (int k = 0; k < spec.test_samples; ++k) {
        Vector6d q = Vector6d::Zero();
        q[test.coordinate] = test.amplitude * (-1.0 + 2.0 * k / (spec.test_samples - 1));
        const Pose pose = Pose::from_vector(q);
        if (motor_commands(model, pose, strategy, command, report) == Status::Ok) {
          out.poses.push_back(pose);
          ++out.test_poses;
        } else {
          ++out.tests_dropped;
        }
      }
    }
  }
  const std::vector<Pose> drawn = random_combined_poses(spec, 0, static_cast<std::size_t>(spec.random));
  out.random_drawn = drawn.size();
  for (const Pose& pose : drawn)
    if (motor_commands(model, pose, strategy, command, report) == Status::Ok) {
      out.poses.push_back(pose);
      ++out.random_reached;
    }
  return Status::Ok;
}

}  // namespace hexatwist
