// SPDX-License-Identifier: BSD-3-Clause
// One test of the paper's study (§4, Table 1): the rotation about z through +-30 deg, simulated
// twist-free, with the conventional and with the compensated commands, and the observation error
// split into what the twist and what the servos do. The twin of examples/python/05_study.py, which
// plots the runs.
#include <hexatwist/hexatwist.hpp>

#include <cstdio>

int main() {
  using namespace hexatwist;
  const Config config = default_config();  // the seed rig and its study section (configs/seed.yaml)
  const StudyTest test = study_test(config.study, "Rz");
  const Trajectory trajectory = test_trajectory(config.study, test, config.rig.control_period());

  TestRun run;
  SimulationIssue issue;
  if (run_test(config.rig, trajectory, run, issue) != Status::Ok) {
    std::printf("t = %.3f s, leg %d: %s\n", issue.time, issue.limit.leg + 1, describe(issue.status).data());
    return 1;
  }
  std::printf("Rz test: %zu ticks, %.2f s\n", run.compensated.samples.size(), trajectory.duration());
  for (const auto& [name, r] :
       {std::pair{"conventional", &run.conventional}, std::pair{"compensated", &run.compensated}}) {
    const RunMetrics m = run_metrics(config.rig, r->samples);  // what `hexatwist study` reports beside the errors
    std::printf("%-12s  max %.4f mm, rms %.4f mm; twist alone %.4f mm, servos alone %.4f mm; largest torque %.2f N m\n",
                name, 1e3 * r->total.max, 1e3 * r->total.rms, 1e3 * r->twist_only.max, 1e3 * r->tracking_only.max,
                m.max_torque);
  }
  return 0;
}
