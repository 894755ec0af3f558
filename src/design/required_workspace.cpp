// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/design/required_workspace.hpp"

#include <cmath>

#include "design/sampling.hpp"

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

Status required_workspace(const Model& model, const StudySpec& study, const RequiredWorkspaceSpec& spec,
                          Strategy strategy, RequiredWorkspace& out) {
  out = RequiredWorkspace{};
  if (spec.test_samples < 2 || spec.random < 0 || !(spec.linear >= 0.0) || !std::isfinite(spec.linear) ||
      !(spec.angular >= 0.0) || !std::isfinite(spec.angular))
    return Status::NonFiniteInput;
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
