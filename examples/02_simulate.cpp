// SPDX-License-Identifier: BSD-3-Clause
// The servo simulation from C++: a yaw sweep of +-10 deg on the seed platform, closed loop, with
// the conventional and the compensated commands, and the error of point A.
#include <hexatwist/hexatwist.hpp>

#include <algorithm>
#include <cstdio>

int main() {
  using namespace hexatwist;
  const Config config = default_config();  // platform + servo + load + rates (configs/seed.yaml)
  const Rig& rig = config.rig;

  // Home -> +10 deg -> -10 deg -> home about z, jerk-limited, sampled at the control rate.
  const MotionLimits limits{deg2rad(15), deg2rad(45), deg2rad(180)};  // [rad/s, rad/s^2, rad/s^3]
  const Trajectory trajectory = sweep_trajectory(5, deg2rad(10), limits, 0.2, rig.control_period());

  SimulationIssue issue;
  if (check_trajectory(rig, trajectory, issue) != Status::Ok) {  // limits, motor speed, holding torque
    std::printf("t = %.3f s, leg %d: %s\n", issue.time, issue.limit.leg + 1, describe(issue.status).data());
    return 1;
  }
  for (const Strategy strategy : {Strategy::Conventional, Strategy::Compensated}) {
    SimulationOptions options;
    options.strategy = strategy;
    std::vector<SimulationSample> samples;  // one per 1 ms tick
    if (simulate(rig, trajectory, options, samples, issue) != Status::Ok) return 2;
    double worst = 0.0, worst_twist_only = 0.0;
    for (const SimulationSample& s : samples) {
      worst = std::max(worst, s.error);
      worst_twist_only = std::max(worst_twist_only, s.error_twist_only);
    }
    std::printf("%-12s  %.2f s simulated: point A misses by up to %.4f mm (with perfect servos %.1e mm)\n",
                strategy == Strategy::Conventional ? "conventional" : "compensated", trajectory.duration(), 1e3 * worst,
                1e3 * worst_twist_only);
  }
}
